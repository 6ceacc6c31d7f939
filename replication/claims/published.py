"""Published numbers, each with what it is, so that a reproduced value is set only beside its own kind.

A ``Published`` value says what was measured (``kind``: "held-out", "training loss", "rollout energy",
"exact"), where it is printed (``source``), which of our unit metrics is of the same kind
(``metric``), and the conditions a comparison needs (``conditions``: evaluation settings such as the
number of initial conditions and the horizon, matched against the unit's recorded ``eval_config``), and
the model it was measured on: its hidden widths (``width``) and its training samples (``samples``).
``like_for_like(cfg, hidden, samples)`` is true only when the kinds match, every condition holds, the unit's
widths are the published model's and it trained on at least half the published samples
(``BUDGET_SHARE``); otherwise the number is context, never a target. A number measured on other data (``other_data=True``) is always
context. A number that no paper or its repository prints is not a ``Published``: it has no place here.
"""
from __future__ import annotations

from dataclasses import dataclass

# a unit is measured like for like only when it trained on at least this share of the published samples
BUDGET_SHARE = 0.5


@dataclass(frozen=True)
class Published:
    value: float
    kind: str
    source: str
    metric: str = ""                  # our metric of the same kind; "" = none we measure
    conditions: tuple = ()            # ((eval_config key, value), ...)
    other_data: bool = False
    note: str = ""
    width: tuple = ()                 # the published model's hidden widths; () = not stated
    samples: float = 0.0              # the published model's training samples; 0 = not stated

    def like_for_like(self, eval_config: dict | None, hidden=None, samples=None) -> tuple[bool, str]:
        """(comparable, why not) against a unit's evaluation config, hidden widths and training samples."""
        if self.other_data:
            return False, "measured on other data"
        if not self.metric:
            return False, f"we measure no {self.kind}"
        cfg = eval_config or {}
        off = [f"{k} {cfg.get(k, 'unset')} (published {v})" for k, v in self.conditions if cfg.get(k) != v]
        if self.width and tuple(hidden or ()) != tuple(self.width):
            off.append(f"width {'x'.join(map(str, hidden or ())) or 'unset'} (published "
                       f"{'x'.join(map(str, self.width))})")
        if self.samples and not (samples or 0) >= BUDGET_SHARE * self.samples:
            off.append(f"{float(samples or 0):.3g} training samples (published {self.samples:.3g})")
        if off:
            return False, "ours: " + ", ".join(off)
        return True, ""

    @classmethod
    def from_dict(cls, d: dict) -> Published:
        """From `to_dict`'s output (claims.json); unknown keys ignored."""
        return cls(value=d.get("value"), kind=str(d.get("kind") or "unknown"), source=str(d.get("source") or ""),
                   metric=str(d.get("metric") or ""), conditions=tuple((d.get("conditions") or {}).items()),
                   other_data=bool(d.get("other_data")), note=str(d.get("note") or ""),
                   width=tuple(d.get("width") or ()), samples=float(d.get("samples") or 0.0))

    def to_dict(self) -> dict:
        return {"value": self.value, "kind": self.kind, "source": self.source, "metric": self.metric,
                "conditions": dict(self.conditions), "other_data": self.other_data, "note": self.note,
                "width": list(self.width), "samples": self.samples}
