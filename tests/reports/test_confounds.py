"""What a claim's comparison does not control (`reports.confounds`), on its page and in the scorecard's flags: the
compared models' parameter counts from their recorded specs, a flag where they differ, every seed of a model
below its bar."""
import json
import shutil

import pytest
from markdown_tables import claim_rows, md_table
from result_fixtures import SEEDS, checksum, write_json

from lagbench.reports import build_report

WIDE = [64, 64]


def mlp_parameters(sizes: list[int]) -> int:
    """Weights and biases of a plain MLP of these layer widths, input first."""
    return sum(a * b + b for a, b in zip(sizes, sizes[1:], strict=False))


@pytest.fixture(scope="module")
def report(small_results_dir, tmp_path_factory) -> str:
    """The fixtures with dp_loss's baseline WIDE (checksums rewritten): REPORT.md of their report."""
    root = tmp_path_factory.mktemp("wide")
    shutil.copytree(small_results_dir, root / "res")
    for f in (root / "res" / "units" / "dp_loss").glob("*/baseline/seed*/result.json"):
        r = json.loads(f.read_text())
        r["model_spec"]["hidden"] = WIDE
        r["checksum"] = checksum(r)
        write_json(f, r)
    return build_report(root / "res", root / "out", pdf=False)["markdown"].read_text()


def test_the_compared_models_sizes_are_counted_from_their_specs_and_a_difference_flagged(report):
    # the fixture's double pendulum: dof 2, the MLP sees q and qdot; the LNN outputs a scalar, the baseline qddot
    lnn, baseline = mlp_parameters([4, 16, 16, 1]), mlp_parameters([4, *WIDE, 2])
    sizes = md_table(report, "dp_loss: the compared models' sizes and budgets").set_index("model")
    assert sizes.loc["lnn", "parameters"] == f"{lnn:,}" and sizes.loc["baseline", "parameters"] == f"{baseline:,}"
    assert sizes.loc["baseline", "hidden widths"] == "x".join(map(str, WIDE))
    flags = claim_rows(report, "Scorecard")["dp_loss"]["flags"]
    assert f"sizes differ: baseline {baseline:,} vs lnn {lnn:,} parameters" in flags, flags
    assert f"does not control model size (baseline {baseline:,} vs lnn {lnn:,} parameters)" in report


def test_every_seed_of_a_model_below_its_bar_is_on_the_claims_page(report):
    seeds = md_table(report, "dp_energy: every seed of a model below its competence bar")
    lnn = seeds[seeds["model"] == "lnn"]   # the fixture's rollouts record no divergence count: no seed passes
    assert sorted(lnn["seed"]) == sorted(str(s) for s in SEEDS * 2) and set(lnn["bar"]) == {"FAILED"}
    assert set(lnn["framework"]) == {"jax", "torch"}


def test_sizes_are_set_against_each_other_only_within_a_part():
    """A claim of two systems (a part each): the larger system's pair never against the smaller system's."""
    from types import SimpleNamespace

    from lagbench.reports.confounds import SIZE_RATIO, sizes_differ

    parts = [{"name": "spring", "reads": ["hnn_spring", "baseline_spring"]},
             {"name": "pendulum", "reads": ["hnn_pendulum", "baseline_pendulum"]},
             {"name": "positive", "reads": ["hnn_spring"], "check": True}]
    res = SimpleNamespace(verdicts={"c": {"parts": parts}})
    small = 1000.0
    params = {"hnn_spring": 10 * small, "baseline_spring": 10 * small * SIZE_RATIO * 0.9,   # within the ratio
              "hnn_pendulum": small, "baseline_pendulum": small * SIZE_RATIO * 2}
    sizes = {m: {"params": p} for m, p in params.items()}
    assert sizes_differ(res, {"id": "c"}, sizes) == (f"baseline_pendulum {int(small * SIZE_RATIO * 2):,} vs "
                                                     f"hnn_pendulum {int(small):,} parameters")
    sizes["baseline_spring"]["params"] = 10 * small * SIZE_RATIO * 3   # both parts' pairs differ: each named
    assert sizes_differ(res, {"id": "c"}, sizes).count(" vs ") == 2
    res.verdicts["c"]["parts"] = []   # no parts: the claim's models as one set
    assert sizes_differ(res, {"id": "c"}, sizes).startswith(f"baseline_spring {int(10 * small * SIZE_RATIO * 3):,} "
                                                           f"vs hnn_pendulum")


def test_words_of_a_claim_that_no_part_tests_are_named_on_its_page_and_only_there():
    """Claim 9 says DeLaN's advantage is largest ("most") on unseen trajectories and few samples; its parts ask
    only that DeLaN is better: its page says so, another claim's does not."""
    from types import SimpleNamespace

    from lagbench.replication.claims import CLAIMS
    from lagbench.reports.confounds import WORDS_UNTESTED, not_tested

    assert set(WORDS_UNTESTED) <= set(CLAIMS)
    assert "most" in CLAIMS["delan_arm"].title
    res = SimpleNamespace(verdicts={})
    said = not_tested(res, {"id": "delan_arm", "metric": "torque_mse_test"}, sizes={})
    assert '"most on unseen trajectories and few samples"' in said and "no part compares" in said
    assert "no part" not in not_tested(res, {"id": "dp_loss", "metric": "heldout_l1"}, sizes={})
