"""Grouping of claims into the report's thematic sections, from the fields of each claims.json record.

A claim goes to the first theme whose predicate accepts it (on ``system``, ``models``, ``id``, ``title``);
``Further claims`` takes the rest. Themes with no claim still appear and read "not run" (except the
catch-all), so a reader sees what the suite covers even when a run skipped it.
"""

from __future__ import annotations

from collections.abc import Callable


def _systems(claim: dict) -> list[str]:
    s = claim.get("system")
    items = s if isinstance(s, list) else [s]
    return [str(x).lower() for x in items if x]


def _models(claim: dict) -> list[str]:
    return [str(m).lower() for m in claim.get("models") or []]


def _words(claim: dict) -> str:
    return f"{claim.get('id', '')} {claim.get('title', '')}".lower()


def is_delan(c: dict) -> bool:
    return any(m.startswith("delan") for m in _models(c))


def is_study(c: dict) -> bool:
    return any("_init-" in m or "_act-" in m for m in _models(c)) or any(
        w in _words(c) for w in ("init", "activation"))


def is_double_pendulum(c: dict) -> bool:
    return "double_pendulum" in _systems(c)


def is_relativistic(c: dict) -> bool:
    return any("relativ" in s for s in _systems(c))


def is_wave(c: dict) -> bool:
    return any("wave" in s for s in _systems(c)) or "lgn" in _models(c)


THEMES: list[tuple[str, str, str, Callable[[dict], bool]]] = [
    ("double_pendulum", "Double pendulum",
     "Held-out loss and energy conservation of the LNN against the baseline (LNN §5).", is_double_pendulum),
    ("relativistic", "Relativistic particle: canonical against arbitrary coordinates",
     "HNN on (q, q̇), HNN on canonical (q, p) and LNN on (q, q̇) (LNN §5).", is_relativistic),
    ("wave", "Wave equation (Lagrangian graph network)",
     "Learned against true field, energy over time, transfer from the training grid to a larger one.",
     is_wave),
    ("delan", "DeLaN: structured Lagrangians and robot-arm inverse dynamics",
     "Torque error on training-like and unseen trajectories against a feed-forward network, data "
     "efficiency, and the inertial/Coriolis/gravity decomposition against truth (DeLaN; LNN Table 1).",
     is_delan),
    ("studies", "Initialisation and activation studies",
     "Training curves per initialisation scheme and per activation (LNN Appendix C).", is_study),
    ("other", "Further claims", "Claims outside the themes above.", lambda c: True),
]
PRIORITY = ["delan", "studies", "double_pendulum", "relativistic", "wave", "other"]


def assign(claims: list[dict]) -> dict[str, list[dict]]:
    """``{theme key: [claims]}`` in the order of :data:`THEMES`; each claim in exactly one theme."""
    preds = {key: pred for key, _, _, pred in THEMES}
    out: dict[str, list[dict]] = {key: [] for key, *_ in THEMES}
    for claim in claims:
        key = next(k for k in PRIORITY if preds[k](claim))
        out[key].append(claim)
    return out
