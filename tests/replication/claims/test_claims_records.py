"""The claim records themselves: kinds, parts and variants name real models, a pooled claim's seed counts
follow its stated power rule, every claim its seed rule, and a variant differs from the paper's model only in its departure."""
import ast
from pathlib import Path

import pytest

from lagbench.replication.claims import CLAIMS, PROFILES, seed_rule
from lagbench.replication.claims.base import Claim
from lagbench.replication.claims.stats import seeds_needed


def test_checks_are_apart_from_the_paper_claims():
    """A check (an implementation or numerics check) is counted apart from the paper claims."""
    import pandas as pd

    from lagbench.replication.claims.verdicts import headline, judge

    checks = {c.id for c in CLAIMS.values() if c.kind == "check"}
    assert {"appendix_b", "precision"} <= checks
    counted = headline([judge(c, pd.DataFrame(), None) for c in CLAIMS.values()])
    assert sum(counted["checks"].values()) == len(checks) and sum(counted["claims"].values()) == len(CLAIMS) - len(checks)


def _top_level_problems(tree) -> list:
    """What makes a module more than literals: a top-level statement that changes a value after it is written
    (an item or attribute assigned, an augmented assignment, a bare call such as `d.update(...)`), or a read
    of the adopted tuning or of a file."""
    out = []
    for node in tree.body:
        targets = node.targets if isinstance(node, ast.Assign) else [node.target] if isinstance(
            node, ast.AnnAssign | ast.AugAssign) else []
        if isinstance(node, ast.AugAssign) or any(isinstance(t, ast.Subscript | ast.Attribute) for t in targets):
            out.append(f"line {node.lineno}: changes a value after it is written")
        if isinstance(node, ast.Expr) and not isinstance(node.value, ast.Constant):
            out.append(f"line {node.lineno}: a bare call at import")
        if isinstance(node, ast.ImportFrom | ast.Import):
            names = {a.name for a in node.names} | {node.module or ""} if isinstance(node, ast.ImportFrom) else {
                a.name for a in node.names}
            if names & {"tuned", "resolved", "registration", "verdicts", "json", "pathlib"}:
                out.append(f"line {node.lineno}: imports {sorted(names)}")
    for node in ast.walk(tree):
        name = node.attr if isinstance(node, ast.Attribute) else node.id if isinstance(node, ast.Name) else ""
        if name in ("open", "read_text", "read_bytes", "records"):
            out.append(f"line {node.lineno}: reads a file ({name})")
    return out


def test_claim_files_and_their_shared_settings_are_literals():
    """What a claim file writes is what the claim holds: no claim module, nor a settings module a claim includes
    (`double_pendulum`, `two_link_arm`, `pace_study`), changes a value after writing it or reads a file or the
    adopted tuning at import; the adopted tuning is applied in one place, `claims.resolved`."""
    import sys

    from lagbench.replication import claims as package

    folder = Path(package.__file__).parent
    claims = {id(c) for c in CLAIMS.values()}
    modules = {m.__name__.rsplit(".", 1)[1] for m in list(sys.modules.values())
               if m.__name__.startswith(package.__name__ + ".") and id(getattr(m, "CLAIM", None)) in claims}
    assert len(modules) == len(CLAIMS)
    for name in sorted(modules):   # the settings modules the claims include
        tree = ast.parse((folder / f"{name}.py").read_text())
        modules |= {a.name for n in ast.walk(tree) if isinstance(n, ast.ImportFrom) and n.module == package.__name__
                    for a in n.names}
    assert {"double_pendulum", "two_link_arm", "pace_study"} <= modules
    problems = {name: _top_level_problems(ast.parse((folder / f"{name}.py").read_text())) for name in sorted(modules)}
    assert not {k: v for k, v in problems.items() if v}, problems


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
    """The seed rule (`seed_rule`), fixed before a test run: profiles of record give an interval at most 1.25
    seed spreads wide each way (5 seeds); pooled claims meet their power rule."""
    claim = CLAIMS[cid]
    for profile in PROFILES:
        assert claim.n_seeds(profile) >= seed_rule.required(claim, profile), (profile, claim.n_seeds(profile))
        assert f"{claim.n_seeds(profile)} seed" in seed_rule.describe(claim, profile)


def test_the_seed_rule_follows_from_the_interval():
    """The half-width of the 90 % interval of a ratio, in seed standard deviations of the log metric, against
    the interval `stats.ratio_interval` really gives on seeds of equal spread; 5 seeds of record."""
    import numpy as np

    from lagbench.replication.claims.stats import Stat, ratio_interval

    for n in (2, 3, 5):
        z = np.linspace(-1, 1, n)
        a = 10 ** (z / z.std(ddof=1))     # log10 standard deviation exactly 1 in each model
        iv = ratio_interval(Stat.of(a), Stat.of(a), "a/a")
        assert np.log10(iv.hi) == pytest.approx(seed_rule.halfwidth(n), rel=1e-9)
    assert seed_rule.halfwidth(2) > seed_rule.halfwidth(3) > seed_rule.halfwidth(5)
    assert seed_rule.RECORD_SEEDS == 5 and seed_rule.halfwidth(4) > seed_rule.RECORD_HALFWIDTH >= seed_rule.halfwidth(5)


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
    from lagbench.replication.claims.parts import Part
    from lagbench.replication.claims.rules import bound

    c = CLAIMS["dp_loss"]
    with pytest.raises(ValueError, match="unknown models"):
        Claim(**{**c.__dict__, "parts": (Part("x", bound("m", upper=1.0), reads=("nobody",)),)})
    with pytest.raises(ValueError, match="every part is a check"):
        Claim(**{**c.__dict__, "parts": (Part("x", bound("m", upper=1.0), reads=("lnn",), check=True),)})


def test_claim_2s_registered_matched_level_is_the_adopted_baselines_score():
    """Claim 2 reads its models at a held-out level written in its file: the development score of the baseline's
    adopted choice (the search claim 1's models were tuned by) under each profile that decides at matched accuracy."""
    from lagbench.replication.claims.resolved import resolved

    for profile in ("quick", "full"):
        adopted = resolved(CLAIMS["dp_loss"], profile).model("baseline").adopted
        assert adopted is not None and adopted.claim == "dp_loss"
        assert CLAIMS["dp_energy"].evaluation_config(profile)["match_heldout_l1"] == adopted.score
