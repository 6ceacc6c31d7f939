"""The claim records themselves: kinds, parts and variants name real models, a pooled claim's seed counts
follow its stated power rule, and a variant differs from the paper's model only in its departure."""
import pytest

from replication.claims import CLAIMS, PROFILES
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
