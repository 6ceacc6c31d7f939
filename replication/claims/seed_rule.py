"""How many test seeds a claim runs, fixed by a stated rule before its test run (and so registered with it).

A claim whose rule reads each seed as a replication ("for every pair of seeds": the seed range of each
model) decides on that range. The range [min, max] of n independent seeds covers a model's median over
seeds with probability 1 - 2^(1 - n) (`median_coverage`): 50 % at 2 seeds, 75 % at 3, 93.75 % at 5. Profiles
of record (`full`, `paper`) run at least `RECORD_SEEDS` (coverage at least `RECORD_COVERAGE`); `quick` runs
`PRELIMINARY_SEEDS`, a preliminary profile its report says is one; `smoke` decides nothing. A pooled claim (a pace study)
reads its seeds as one sample: it runs at least `stats.seeds_needed(0.05, rivals)` in every profile that
decides. A check (an implementation or numerics check) needs no count of its own.
`describe(claim, profile) -> str`: the rule and what the count gives, for claims.json and the report.
"""
from __future__ import annotations

from replication.claims.stats import seeds_needed

RECORD_PROFILES = ("full", "paper")
RECORD_COVERAGE = 0.9
PRELIMINARY = ("quick",)
# the preliminary profile's seeds a model: 2, so that `quick` fits its 45 minutes on 2 cores; their range
# covers a model's median with probability 50 % (its report says it is preliminary)
PRELIMINARY_SEEDS = 2


def median_coverage(n: int) -> float:
    """The probability that the range of n independent draws covers their distribution's median."""
    return 1.0 - 2.0 ** (1 - n) if n >= 1 else 0.0


def record_seeds(coverage: float = RECORD_COVERAGE) -> int:
    n = 1
    while median_coverage(n) < coverage:
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
    return (f"{n} seeds ({kind}): a model's seed range covers its median with probability "
            f"{100 * median_coverage(n):.4g} %" + (f" (at least {100 * RECORD_COVERAGE:g} % of record)"
                                                   if profile in RECORD_PROFILES else ""))
