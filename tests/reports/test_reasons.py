"""The scorecard's reasons (`reports.reasons`): each part's category from the verdict record the runner's rules
write, "did not learn" where a model's error sits at the null predictor's, and a published number far from
ours flagged."""
import json
import shutil

import pytest
from markdown_tables import claim_rows, md_table
from result_fixtures import SEEDS, checksum, write_json

from lagbench.replication.claims.rules import Stat, similar
from lagbench.reports import build_report
from lagbench.reports.reasons import AT_NULL, BELOW_BAR, DECIDED, NEAR, NEAR_T, STRADDLES, part_why


def _part(a: list[float], b: list[float], within: float = 1.5) -> dict:
    """A part of the rule `similar(a, b, within)` as judge() records it, decided on seeds `a` and `b`."""
    o = similar("a", "b", within, "m")({"a": {"m": Stat.of(a)}, "b": {"m": Stat.of(b)}})
    iv = {**o.interval.to_dict(), "thresholds": list(o.thresholds), "distance": o.distance}
    return {"name": "similar", "reads": ["a", "b"], "controls": [], "by_framework": {"jax": o.verdict},
            "reason": {"jax": o.reason}, "interval": {"jax": iv}}


PUBLISHED = 4.5   # a tenth of 0.9 x the fixture's null (50)
PASSED = {"jax": {m: {"passed": True, "per_seed": [{"seed": 0, "passed": True}]} for m in "ab"}}


def test_each_part_falls_in_the_category_its_interval_and_threshold_say():
    wide = _part([1.0, 1.6, 0.7], [1.0, 1.02, 0.98])   # noisy: the interval holds a threshold
    cat, words = part_why({"competence": PASSED}, wide, "jax", {})
    assert cat == STRADDLES and wide["by_framework"]["jax"] == "inconclusive"
    assert "90 % confidence interval" in words and "over 3 seeds each" in words
    clear = _part([1.0, 1.01, 0.99], [1.0, 1.01, 0.99])   # equal: the ratio 1, far inside [1/1.5, 1.5]
    assert part_why({"competence": PASSED}, clear, "jax", {})[0] == DECIDED
    near = _part([1.30, 1.31, 1.29], [1.0, 1.0, 1.0])   # inside the band, its upper end within NEAR of 1.5
    assert near["by_framework"]["jax"] == "reproduced" and near["interval"]["jax"]["distance"] < NEAR
    cat, words = part_why({"competence": PASSED}, near, "jax", {})
    assert cat == NEAR_T and "% from it" in words


def test_a_model_below_its_bar_reads_k_of_n_seeds_and_did_not_learn_where_named():
    comp = {"jax": {"a": PASSED["jax"]["a"],
                    "b": {"passed": False, "per_seed": [{"seed": 0, "passed": True}, {"seed": 1, "passed": False},
                                                        {"seed": 2, "passed": False}]}}}
    part = _part([1.0, 1.1, 0.9], [1.0, 1.0, 1.0])
    assert part_why({"competence": comp}, part, "jax", {}) == (BELOW_BAR, "b passed on 1/3 seeds")
    cat, words = part_why({"competence": comp}, part, "jax", {"b": "heldout_l1 9, null 10"})
    assert words == "b passed on 1/3 seeds (did not learn)"


@pytest.fixture(scope="module")
def at_null(small_results_dir, tmp_path_factory) -> str:
    """The fixtures with dp_loss's LNN at 0.9 x its null predictor's error (50) on every seed (checksums
    rewritten) and a published held-out value of PUBLISHED: REPORT.md of the report built from them."""
    root = tmp_path_factory.mktemp("at_null")
    shutil.copytree(small_results_dir, root / "res")
    claims = json.loads((root / "res" / "claims.json").read_text())
    claims["claims"][0]["published"]["lnn"] = {"value": PUBLISHED, "kind": "held-out", "metric": "heldout_l1",
                                               "source": "a test's own number"}
    write_json(root / "res" / "claims.json", claims)
    for f in (root / "res" / "units" / "dp_loss").glob("*/lnn/seed*/result.json"):
        r = json.loads(f.read_text())
        if int(r["seed"]) in SEEDS:   # the corrupt unit stays corrupt
            r["metrics"]["heldout_l1"] = 0.9 * r["metrics"]["null_heldout_l1"]
            r["checksum"] = checksum(r)
            write_json(f, r)
    return build_report(root / "res", root / "out", pdf=False)["markdown"].read_text()


def test_a_model_at_its_null_did_not_learn_and_a_number_far_from_published_is_flagged(at_null):
    assert 0.9 >= AT_NULL
    row = claim_rows(at_null, "Scorecard")["dp_loss"]
    assert row["verdict"].startswith("inconclusive")
    n = len(SEEDS)
    assert f"BELOW BAR (similar held-out loss): lnn passed on 0/{n} seeds (did not learn)" in row["why"], row["why"]
    ratio = 0.9 * 50.0 / PUBLISHED
    assert f"far from published: lnn {ratio:g}x its published {PUBLISHED:g}" in row["flags"], row["flags"]
    assert "did not learn: lnn (heldout_l1 45, null 50)" in row["flags"]
    assert row["published"] == f"{PUBLISHED:g} (held-out; like for like)"   # no width or budget stated
    table = md_table(at_null, "Published numbers beside ours").set_index(["claim", "model"])
    assert table.loc[("dp_loss", "lnn"), "ours / published"] == f"{ratio:g}x"
    assert "from: a test's own number" in table.loc[("dp_loss", "lnn"), "published"]
