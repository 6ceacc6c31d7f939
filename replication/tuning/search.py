"""The declared search: the same knobs and the same number of configurations for every model of a claim.

`KNOBS`: each knob's values, as multipliers of (or alternatives to) the model's registered setting:
  lr      peak learning rate x {1/3, 1, 3} (a scouting round's rate with it)
  width   every hidden layer's width x {1/2, 1, 2} (at least 1)
The sample budget, the restarts and the input scaling stay the registered ones: a knob that changed the
budget (restarts or none) would compare configurations at unequal budgets, and input scales are per system.
`grid() -> [knob values]`: every combination (`SIZE`), the registered setting first, then the others in the
knobs' order; the same list for every model. `lagbench tune` tries all of them.
`extensions(tried, chosen) -> [knob values]`: the declared edge rule. For each chosen configuration whose value
of a knob is the smallest or the largest tried, the configuration one `STEP` further in that direction (lr x or
/ 3, width x or / 2, the other knob as chosen), not yet tried; `lagbench tune` tries the union of them for
every model alike, once. `EDGE_LIMITS[(claim, profile)]` bounds a knob where a step further would cost more
training than the profile's time allows (for every model of the claim alike); `stopped(...)` gives the points
the bound kept out, for the ledger.
`configs(n, seed=0) -> [knob values]`: the registered setting first (all multipliers 1), then n - 1 other
combinations drawn without replacement (generator `seed`); the same list for every model (`lagbench fit
--tune N`, and a partial search that no claim may adopt).
`sweep(widths) -> [knob values]`: a width sweep, the registered setting first, then each width multiplier at the
registered rate (`lagbench tune --widths`): how far a model's error falls as it widens, the same for every model.
`apply(entry, base, profile, knobs) -> ModelEntry`: the model with those knob values under `profile`.
"""
from __future__ import annotations

import itertools
import math

import numpy as np

from lagbench.replication.claims.tuned import scaled_widths, with_knobs

__all__ = ["EDGE_LIMITS", "KNOBS", "REGISTERED", "SIZE", "STEP", "apply", "configs", "extensions", "grid", "scaled_widths",
           "stopped", "sweep"]

KNOBS = {"lr": (1 / 3, 1.0, 3.0), "width": (0.5, 1.0, 2.0)}
REGISTERED = {"lr": 1.0, "width": 1.0}
SIZE = math.prod(len(v) for v in KNOBS.values())   # the search's combinations
STEP = {"lr": 3.0, "width": 2.0}   # the ratio between neighbouring values of each knob
# The largest value of a knob the edge step may reach, per (claim, profile), the same for every model of the
# claim; declared with its measured cost in docs/decisions/tuning_edge_limits.md before the points were trained.
EDGE_LIMITS = {("dp_loss", "full"): {"width": 2.0}}


def grid() -> list[dict]:
    every = [dict(zip(KNOBS, values, strict=True)) for values in itertools.product(*KNOBS.values())]
    return [dict(REGISTERED), *[c for c in every if c != REGISTERED]]


def extensions(tried: list[dict], chosen: list[dict], limits: dict | None = None) -> list[dict]:
    return [p for p in _steps(tried, chosen) if _within(p, limits or {})]


def stopped(tried: list[dict], chosen: list[dict], limits: dict | None = None) -> list[dict]:
    return [p for p in _steps(tried, chosen) if not _within(p, limits or {})]


def _within(point: dict, limits: dict) -> bool:
    return all(point[k] <= v or math.isclose(point[k], v) for k, v in limits.items())


def _steps(tried: list[dict], chosen: list[dict]) -> list[dict]:
    out = []
    for c in chosen:
        for knob, step in STEP.items():
            values = [t[knob] for t in tried]
            for edge, factor in ((min(values), 1 / step), (max(values), step)):
                if math.isclose(c[knob], edge):
                    point = {**c, knob: edge * factor}
                    if not any(_same(point, t) for t in (*tried, *out)):
                        out.append(point)
    return out


def _same(a: dict, b: dict) -> bool:
    return all(math.isclose(a[k], b[k]) for k in KNOBS)


def configs(n: int, seed: int = 0) -> list[dict]:
    every = grid()
    if not 1 <= n <= len(every):
        raise ValueError(f"--configs: {n!r} is not valid; expected 1 to {len(every)} (the search's combinations)")
    others = every[1:]
    order = np.random.default_rng(seed).permutation(len(others))
    return [dict(REGISTERED), *[others[i] for i in order[:n - 1]]]


def sweep(widths) -> list[dict]:
    try:
        values = [float(w) for w in widths]
    except (TypeError, ValueError):
        values = []
    if not values or not all(0 < w < float("inf") for w in values):
        raise ValueError(f"--widths: {','.join(map(str, widths))!r} is not valid; expected positive width multipliers")
    return [dict(REGISTERED), *[{"lr": 1.0, "width": w} for w in dict.fromkeys(values) if w != 1.0]]


def apply(entry, base, profile: str, knobs: dict):
    """`entry` (a claims.base.ModelEntry) with the knob values applied to its protocol and widths under
    `profile` (its other profiles unchanged): the same function applies an adopted choice."""
    return with_knobs(entry, base, profile, knobs)
