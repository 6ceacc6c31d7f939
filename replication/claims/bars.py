"""Competence bars: what a model must show, seed by seed, before a claim about it can be judged.

A ``Bar`` names the models it covers, an error metric measured on the model's own training
distribution, and the null predictor's value of that metric that each unit records beside it
(``null_<metric>``: the better of predicting zero and predicting the held-out mean target, see
``replication.evaluation.metrics.null_errors``; for the wave pulse, the pulse left where it started).
A bar reads each seed on its own (``seeds``: one row per unit of the model in one framework, failed units
included, as ``{"seed", "status", <metric>: value, ...}``). A seed passes when its unit finished, its
metric is at most ``fraction`` x its own null's, and (``max_diverged``, for claims that read rollouts) it
has at most that many diverged rollouts (metric ``n_diverged``); with ``metric=None`` only the rollouts
are checked. A failed unit, a missing or NaN metric, a diverged (+inf) error: each is a failing seed, never
dropped. A model passes when at least ``SHARE`` of its seeds pass: every seed, in every profile (so a good
seed cannot hide one at the null, and a model whose seed failed never counts as one that learned).
``need="any"`` asks only one of the bar's models to pass (a study of which init or activation learns at all
needs one that did).

A model below its bar makes the parts that read it "inconclusive", never "reproduced" or "not reproduced":
a model that has not learned its task says nothing about the paper.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

FRACTION = 0.1   # default: at most a tenth of the null predictor's error
SHARE = 1.0      # the share of a model's seeds that must pass: all of them


def _num(x) -> float | None:
    try:
        v = float(x)
    except (TypeError, ValueError):
        return None
    return None if math.isnan(v) else v


@dataclass(frozen=True)
class Bar:
    models: tuple
    metric: str | None = "heldout_l1"
    fraction: float = FRACTION
    max_diverged: int | None = None   # None: rollouts not read by this bar; else at most this many a seed
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
        return f"{who}: {', '.join(parts)}, on {'every seed' if SHARE == 1 else f'{SHARE:.0%} of seeds'}"

    def check_seed(self, row: dict) -> tuple[bool, str, float | None]:
        """(passed, why, value) of one seed's unit row."""
        seed = row.get("seed")
        if row.get("status", "ok") != "ok":
            return False, f"seed {seed} failed ({row.get('failure') or 'no result'})", None
        why, value = [], None
        if self.metric:
            value, null = _num(row.get(self.metric)), _num(row.get(self.null_metric))
            if value is None or null is None:
                return False, f"seed {seed}: {self.metric} or its null not recorded (or NaN)", value
            if not value <= self.fraction * null:
                return False, f"seed {seed}: {value:.3g} > {self.fraction:g} x null {null:.3g}", value
            why.append(f"seed {seed}: {value:.3g} <= {self.fraction:g} x null {null:.3g}")
        if self.max_diverged is not None:
            n_div = _num(row.get("n_diverged"))
            if n_div is None or n_div > self.max_diverged:
                return False, f"seed {seed}: {'unknown' if n_div is None else int(n_div)} diverged rollouts", value
            why.append(f"seed {seed}: {int(n_div)} diverged rollouts")
        return True, "; ".join(why), value

    def check(self, label: str, seeds: list) -> tuple[bool, str, list]:
        """(passed, why, per seed [{seed, passed, value, why}]) for one model's seed rows. ``why`` names every
        seed's value when any seed fails, else the pass count and the worst passing value."""
        per = [dict(zip(("passed", "why", "value"), self.check_seed(r), strict=True), seed=r.get("seed")) for r in seeds]
        if not per:
            return False, f"{label}: no seed recorded", per
        k = sum(p["passed"] for p in per)
        passed = k >= SHARE * len(per)
        what = self.metric or "rollouts"
        if k < len(per):
            return passed, f"{label}: {what} passes on {k}/{len(per)} seeds: " + "; ".join(p["why"] for p in per), per
        vals = [p["value"] for p in per if p["value"] is not None]
        worst = f" (worst {max(vals):.3g})" if vals else ""
        return passed, f"{label}: {what} passes on {k}/{len(per)} seeds{worst}: " + "; ".join(p["why"] for p in per), per


def competence(bars, seeds: dict) -> tuple[bool, list[str], dict]:
    """Apply every bar to ``seeds = {label: [seed row, ...]}`` (one framework).

    Returns (all bars met, reasons of the failures, {label: (passed all its bars, why, per seed)} for each
    model with a bar; a model under several bars passes a seed only if the seed passes them all).
    A model a bar names but ``seeds`` lacks is not judged here (the verdict reports it missing)."""
    ok, why, per = True, [], {}
    for bar in bars:
        present = [x for x in bar.models if x in seeds]
        res = {x: bar.check(x, seeds[x]) for x in present}
        for x, (p, w, s) in res.items():
            p0, w0, s0 = per.get(x, (True, "", None))
            merged = s if s0 is None else [{**a, "passed": a["passed"] and b["passed"], "why": f"{a['why']}; {b['why']}"}
                                           for a, b in zip(s0, s, strict=True)]
            per[x] = (p0 and p, f"{w0}; {w}" if w0 else w, merged)
        passed = [x for x, (p, _, _) in res.items() if p]
        met = bool(passed) if bar.need == "any" else len(passed) == len(present)
        if present and not met:
            ok = False
            fails = [w for _, (p, w, _) in res.items() if not p]
            why.append(("none of them passed: " if bar.need == "any" else "") + "; ".join(fails))
    return ok, why, per


def added_competence(bars, seeds: dict, known) -> dict:
    """{label: (passed, why, per seed)} for the models of ``seeds`` that are not the claim's (``known``): a
    user's model (`lagbench run --add-model`), held to the claim's first bar's metric, fraction and rollout
    limit. No part reads it: it says how the model fares, never what the claim's verdict is."""
    if not bars:
        return {}
    b = bars[0]
    return {x: Bar((x,), b.metric, b.fraction, b.max_diverged).check(x, seeds[x]) for x in seeds if x not in known}
