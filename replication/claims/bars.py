"""Competence bars: what a model must show before a claim about it can be judged.

A ``Bar`` names the models it covers, an error metric measured on the model's own training
distribution, and the null predictor's value of that metric that each unit records beside it
(``null_<metric>``: the better of predicting zero and predicting the held-out mean target, see
``replication.evaluation.metrics.null_errors``; for the wave pulse, the pulse left where it started). A model
passes when its seed mean is at most ``fraction`` x the null's. ``max_diverged`` bounds the number of
diverged rollouts (metric ``n_diverged``, summed over seeds) for claims that read rollouts; with
``metric=None`` that is all the bar checks. ``need="any"`` asks only one of the models to pass (a study of
which init or activation learns at all needs one that did).

A model below its bar makes its claim "inconclusive", never "reproduced" or "not reproduced":
a model that has not learned its task says nothing about the paper.
"""
from __future__ import annotations

from dataclasses import dataclass

FRACTION = 0.1   # default: at most a tenth of the null predictor's error


@dataclass(frozen=True)
class Bar:
    models: tuple
    metric: str | None = "heldout_l1"
    fraction: float = FRACTION
    max_diverged: int | None = None   # None: rollouts not read by this bar
    need: str = "all"                 # "all" models pass, or "any" one

    def __post_init__(self):
        if self.need not in ("all", "any"):
            raise ValueError(f"Bar.need must be 'all' or 'any', got {self.need!r}")

    @property
    def null_metric(self) -> str:
        return f"null_{self.metric}"

    def describe(self) -> str:
        who = ", ".join(self.models) if self.need == "all" else "one of " + ", ".join(self.models)
        parts = [f"{self.metric} <= {self.fraction:g} x the null predictor's"] if self.metric else []
        if self.max_diverged is not None:
            parts.append(f"at most {self.max_diverged} diverged rollout{'s' if self.max_diverged != 1 else ''}")
        return f"{who}: {', '.join(parts)}"

    def check(self, label: str, s: dict) -> tuple[bool, str]:
        """(passed, why) for one model; ``s`` is {metric: Stat} of its units."""
        why = []
        if self.metric:
            m, null = s.get(self.metric), s.get(self.null_metric)
            if m is None or null is None:
                return False, f"{label}: {self.metric} or its null not recorded"
            if not m.mean <= self.fraction * null.mean:
                return False, f"{label}: {self.metric} {m.mean:.3g} > {self.fraction:g} x null {null.mean:.3g}"
            why.append(f"{label}: {self.metric} {m.mean:.3g} <= {self.fraction:g} x null {null.mean:.3g}")
        if self.max_diverged is not None:
            div = s.get("n_diverged")
            n_div = int(sum(div.values)) if div is not None else None
            if n_div is None or n_div > self.max_diverged:
                return False, f"{label}: {n_div if n_div is not None else 'unknown'} diverged rollouts"
            why.append(f"{label}: {n_div} diverged rollouts")
        return True, "; ".join(why)


def competence(bars, v: dict) -> tuple[bool, list[str], dict]:
    """Apply every bar to ``v = {label: {metric: Stat}}`` (one framework).

    Returns (all bars met, reasons of the failures, {label: (passed all its bars, why)} for each model
    with a bar).
    A model a bar names but ``v`` lacks is not judged here (the verdict reports it missing)."""
    ok, why, per = True, [], {}
    for bar in bars:
        present = [x for x in bar.models if x in v]
        res = {x: bar.check(x, v[x]) for x in present}
        for x, (p, w) in res.items():   # a model under several bars passes only if it passes them all
            p0, w0 = per.get(x, (True, ""))
            per[x] = (p0 and p, f"{w0}; {w}" if w0 else w)
        passed = [x for x, (p, _) in res.items() if p]
        met = bool(passed) if bar.need == "any" else len(passed) == len(present)
        if present and not met:
            ok = False
            fails = [w for _, (p, w) in res.items() if not p]
            why.append(("none of them passed: " if bar.need == "any" else "") + "; ".join(fails))
    return ok, why, per


def added_competence(bars, v: dict, known) -> dict:
    """{label: (passed, why)} for the models of ``v`` that are not the claim's (``known``): a user's model
    (`lagbench run --add-model`), held to the claim's first bar's metric, fraction and rollout limit. No part
    reads it: it says how the model fares, never what the claim's verdict is."""
    if not bars:
        return {}
    b = bars[0]
    return {x: Bar((x,), b.metric, b.fraction, b.max_diverged).check(x, v[x]) for x in v if x not in known}
