"""The claim records themselves: kinds, parts and variants name real models, a pooled claim's seed counts
follow its stated power rule, every claim its seed rule, and a variant differs from the paper's model only in its departure."""
import pytest

from replication.claims import CLAIMS, PROFILES, seed_rule
from replication.claims.base import Claim
from replication.claims.stats import seeds_needed


def test_checks_are_apart_from_the_paper_claims():
    assert {c.id for c in CLAIMS.values() if c.kind == "check"} == {"appendix_b", "precision"}


@pytest.mark.parametrize("cid", [c.id for c in CLAIMS.values() if c.pooled])
def test_pooled_seed_counts_can_reach_the_level_in_every_deciding_profile(cid):
    """The rule: n seeds a model with a complete separation at least 10x below alpha / rivals (two-sided
    exact). smoke decides nothing by design (its models are tiny and untrained)."""
    claim = CLAIMS[cid]
    rivals = max(sum(1 for p in claim.parts if p.name.startswith("faster than")), 1)
    for profile in PROFILES:
        if profile != "smoke":
            assert claim.n_seeds(profile) >= seeds_needed(0.05, rivals), (profile, claim.n_seeds(profile))


@pytest.mark.parametrize("cid", list(CLAIMS))
def test_every_claim_runs_the_seeds_its_stated_rule_requires(cid):
    """The seed rule (`seed_rule`), fixed before a test run: profiles of record give a seed range that covers
    a model's median with at least 90 % probability (5 seeds); pooled claims meet their power rule."""
    claim = CLAIMS[cid]
    for profile in PROFILES:
        assert claim.n_seeds(profile) >= seed_rule.required(claim, profile), (profile, claim.n_seeds(profile))
        assert f"{claim.n_seeds(profile)} seed" in seed_rule.describe(claim, profile)


def test_median_coverage_of_a_seed_range():
    """1 - 2^(1-n), checked against a simulation: the range of n draws of a skewed distribution covers its median."""
    import numpy as np

    rng = np.random.default_rng(0)
    for n in (2, 3, 5):
        x = rng.lognormal(size=(200_000, n))
        covered = np.mean((x.min(1) <= 1.0) & (x.max(1) >= 1.0))   # the lognormal's median is 1
        assert covered == pytest.approx(seed_rule.median_coverage(n), abs=0.005)
    assert seed_rule.RECORD_SEEDS == 5 and seed_rule.median_coverage(3) == 0.75


@pytest.mark.parametrize("cid", [c.id for c in CLAIMS.values() if c.variants])
def test_a_variant_differs_from_the_paper_model_only_in_its_departure(cid):
    """The gamma variants: the same widths, protocol (restarts, rates) and spec in every profile, but for
    the Lorentz-factor input and its input scale."""
    claim = CLAIMS[cid]
    for var in claim.variants:
        for paper, variant in var.replaces:
            a, b = claim.entry(paper), claim.entry(variant)
            for profile in PROFILES:
                assert a.runs_in(profile) == b.runs_in(profile)
                assert a.widths(profile) == b.widths(profile)
                assert a.protocol(claim.protocol(profile), profile) == b.protocol(claim.protocol(profile), profile)
                sa, sb = a.spec_fields(profile), b.spec_fields(profile)
                differ = {k for k in set(sa) | set(sb) if sa.get(k) != sb.get(k)}
                assert differ <= {"lorentz_factor", "input_scale", "extra_inputs", "activation"}, differ
                assert sb.get("lorentz_factor") and not sa.get("lorentz_factor")
                assert sa.get("activation", "softplus") == sb.get("activation", "softplus")
                sa_scale, sb_scale = tuple(sa.get("input_scale", ())), tuple(sb.get("input_scale", ()))
                if sa_scale:   # the same scales, the gamma input's inserted before the extra inputs
                    assert sb_scale[:2] + sb_scale[3:] == sa_scale


def test_a_part_naming_an_unknown_model_is_refused():
    from replication.claims.parts import Part
    from replication.claims.rules import bound

    c = CLAIMS["dp_loss"]
    with pytest.raises(ValueError, match="unknown models"):
        Claim(**{**c.__dict__, "parts": (Part("x", bound("m", upper=1.0), reads=("nobody",)),)})
    with pytest.raises(ValueError, match="every part is a check"):
        Claim(**{**c.__dict__, "parts": (Part("x", bound("m", upper=1.0), reads=("lnn",), check=True),)})
