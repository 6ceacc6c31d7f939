"""How many test seeds a claim runs, fixed by a stated rule before its test run (and so registered with it).

A claim whose rule reads each seed as a replication decides on the confidence interval of a ratio of two
models' metric at `stats.LEVEL` (Welch's t on log ratios: `stats.ratio_interval`). With n seeds a model its
half-width is `halfwidth(n)` = t(0.5 + LEVEL / 2, 2n - 2) x sqrt(2 / n) standard deviations of a seed's log
metric (equal spreads; Welch's degrees of freedom are at most 2n - 2, so the true interval is at least this
wide): 2.92 at 2 seeds, 1.74 at 3, 1.18 at 5. Profiles of record (`full`, `paper`) run the fewest seeds whose
half-width is at most `RECORD_HALFWIDTH` (1.25: a difference of about one and a quarter seed spreads can be
decided), `RECORD_SEEDS` = 5; `quick` runs `PRELIMINARY_SEEDS`, a preliminary profile its report says is one
(its interval is wider, so it decides less, never more); `smoke` decides nothing. A pooled claim (a pace study)
reads its seeds as one sample: it runs at least `stats.seeds_needed(0.05, rivals)` in every profile that
decides. A check (an implementation or numerics check) needs no count of its own.
`describe(claim, profile) -> str`: the rule and what the count gives, for claims.json and the report.
"""
from __future__ import annotations

import math

from scipy.stats import t as student_t

from lagbench.replication.claims.stats import LEVEL, seeds_needed

RECORD_PROFILES = ("full", "paper")
RECORD_HALFWIDTH = 1.25
PRELIMINARY = ("quick",)
# the preliminary profile's seeds a model: 2, so that `quick` fits its 45 minutes on 2 cores; its intervals
# are then 2.5 times wider than at 5 seeds (its report says it is preliminary)
PRELIMINARY_SEEDS = 2


def halfwidth(n: int, level: float = LEVEL) -> float:
    """The interval's half-width in seed standard deviations of the log metric, n seeds a model (inf below 2)."""
    if n < 2:
        return math.inf
    return float(student_t.ppf(0.5 + level / 2, 2 * n - 2)) * math.sqrt(2 / n)


def record_seeds(limit: float = RECORD_HALFWIDTH) -> int:
    n = 2
    while halfwidth(n) > limit:
        n += 1
    return n


RECORD_SEEDS = record_seeds()


def rivals(claim) -> int:
    return sum(1 for p in claim.parts if not p.check)


def required(claim, profile: str) -> int:
    """The fewest seeds the rule allows for the claim under the profile (1: no requirement)."""
    if claim.kind == "check" or profile == "smoke":
        return 1
    if claim.pooled:
        return seeds_needed(0.05, rivals(claim))
    return RECORD_SEEDS if profile in RECORD_PROFILES else 1


def describe(claim, profile: str) -> str:
    n = claim.n_seeds(profile)
    if claim.kind == "check":
        return f"{n} seed(s): a check, no count required"
    if profile == "smoke":
        return f"{n} seed(s): smoke decides nothing"
    if claim.pooled:
        return (f"{n} seeds, pooled: at least {required(claim, profile)} so that a complete separation reaches "
                f"p < 0.05 / {rivals(claim)} rivals with a 10x margin")
    kind = "preliminary" if profile in PRELIMINARY else "of record" if profile in RECORD_PROFILES else "other"
    return (f"{n} seeds ({kind}): the {100 * LEVEL:g} % interval of a ratio spans +-{halfwidth(n):.3g} seed "
            f"standard deviations" + (f" (at most {RECORD_HALFWIDTH:g} of record)" if profile in RECORD_PROFILES
                                      else ""))
