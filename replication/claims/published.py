"""Published numbers, each with what it is, so that a reproduced value is set only beside its own kind.

A ``Published`` value says what was measured (``kind``: "held-out", "training loss", "rollout energy",
"exact"), where it is printed (``source``), which of our unit metrics is of the same kind
(``metric``), and the conditions a comparison needs (``conditions``: evaluation settings such as the
number of initial conditions and the horizon, matched against the unit's recorded ``eval_config``).
``like_for_like(cfg)`` is true only when the kinds match and every condition holds; otherwise the
number is context, never a target. A number measured on other data (``other_data=True``) is always
context. A number that no paper or its repository prints is not a ``Published``: it has no place here.
"""
from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Published:
    value: float
    kind: str
    source: str
    metric: str = ""                  # our metric of the same kind; "" = none we measure
    conditions: tuple = ()            # ((eval_config key, value), ...)
    other_data: bool = False
    note: str = ""

    def like_for_like(self, eval_config: dict | None) -> tuple[bool, str]:
        """(comparable, why not) against a unit's evaluation config."""
        if self.other_data:
            return False, "measured on other data"
        if not self.metric:
            return False, f"we measure no {self.kind}"
        cfg = eval_config or {}
        off = [f"{k} {cfg.get(k, 'unset')} (published {v})" for k, v in self.conditions if cfg.get(k) != v]
        if off:
            return False, "ours: " + ", ".join(off)
        return True, ""

    @classmethod
    def from_dict(cls, d: dict) -> Published:
        """From `to_dict`'s output (claims.json); unknown keys ignored."""
        return cls(value=d.get("value"), kind=str(d.get("kind") or "unknown"), source=str(d.get("source") or ""),
                   metric=str(d.get("metric") or ""), conditions=tuple((d.get("conditions") or {}).items()),
                   other_data=bool(d.get("other_data")), note=str(d.get("note") or ""))

    def to_dict(self) -> dict:
        return {"value": self.value, "kind": self.kind, "source": self.source, "metric": self.metric,
                "conditions": dict(self.conditions), "other_data": self.other_data, "note": self.note}
