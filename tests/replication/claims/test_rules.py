"""The verdict vocabulary (`replication.claims.rules`) and the competence bars, on synthetic seed values:
each rule reproduces, fails, and stays inconclusive where the interval over seeds crosses its threshold;
a part's verdict is never "partly"; each threshold of ours is reported at half and twice its value."""
import math

import pytest

from lagbench.replication.claims.bars import Bar, competence
from lagbench.replication.claims.rules import (
    PART_VERDICTS,
    Outcome,
    Stat,
    below_null,
    better_by,
    bound,
    fails,
    faster,
    matched_better_by,
    never,
    separated,
    similar,
    sooner,
)

M = "m"


def v(**models):
    """v(a=(1, 2, 3), b=(4,)) -> {"a": {"m": Stat}, ...}."""
    return {k: {M: Stat.of(x if isinstance(x, tuple) else (x,))} for k, x in models.items()}


def test_stat_counts_a_diverged_seed_as_infinite_and_drops_nan():
    s = Stat.of([1.0, math.inf, float("nan"), None])
    assert s.n == 2 and s.dropped == 2 and s.mean == math.inf and s.std == math.inf and s.hi == math.inf
    assert Stat.of([math.inf, math.inf]).std == 0.0
    with pytest.raises(ValueError, match="no finite"):
        Stat.of([float("nan")])


def test_separated_means_no_seed_overlap():
    assert separated(Stat.of([1, 2]), Stat.of([3, 4]))
    assert not separated(Stat.of([1, 3.5]), Stat.of([3, 4]))
    assert separated(Stat.of([1, 2]), Stat.of([3, math.inf]))


def test_a_part_verdict_is_never_partly():
    with pytest.raises(ValueError, match="part's verdict"):
        Outcome("partly", "")
    assert "partly" not in PART_VERDICTS


@pytest.mark.parametrize("values, expected, half, twice", [
    (dict(a=(1.0, 1.1, 0.9), b=(5.0, 5.5, 4.5)), "reproduced", "reproduced", "not reproduced"),  # 0.17-0.24
    (dict(a=(1.0, 1.1, 0.9), b=(2.0, 2.1, 1.9)), "not reproduced", "reproduced", "not reproduced"),   # 2x, not 3x
    (dict(a=(5.0, 5.5, 4.5), b=(1.0, 1.1, 0.9)), "not reproduced", "not reproduced", "not reproduced"),
    (dict(a=(1.0, 4.0, 0.5), b=(5.0, 3.0, 6.0)), "inconclusive", "inconclusive", "inconclusive"),   # seeds disagree
    (dict(a=(1.0, 1.1, 0.9), b=(math.inf, 8.0, 9.0)), "reproduced", "reproduced", "reproduced"),   # b diverged once
])
def test_better_by_reads_the_interval_and_reports_its_sensitivity(values, expected, half, twice):
    out = better_by("a", "b", 3.0, M)(v(**values))
    assert out.verdict == expected, out.reason
    assert out.sensitivity == {"factor 1.5": half, "factor 6": twice}
    a, b = values["a"], values["b"]
    assert out.interval.seed_range == (min(x / y for x in a for y in b), max(x / y for x in a for y in b))
    assert out.interval.level == 0.9 and out.interval.seeds == (3, 3) and out.thresholds == (1 / 3,)
    iv = out.interval
    assert out.distance == pytest.approx(min(max(e * 3, 1 / (e * 3)) for e in (iv.lo, iv.hi) if 0 < e < math.inf)) \
        if math.isfinite(iv.hi) else out.distance >= 1


def test_the_interval_widens_as_seeds_fall_and_one_seed_decides_nothing():
    a5, b5 = (1.0, 1.1, 0.9, 1.05, 0.95), (5.0, 5.5, 4.5, 5.25, 4.75)
    wide = [better_by("a", "b", 3.0, M)(v(a=a5[:n], b=b5[:n])).interval for n in (5, 3, 2)]
    assert all(x.hi - x.lo < y.hi - y.lo for x, y in zip(wide, wide[1:], strict=False))
    one = better_by("a", "b", 3.0, M)(v(a=(1.0,), b=(5.0,)))
    assert one.verdict == "inconclusive" and "one seed" in one.interval.method


def test_a_nan_seed_is_never_dropped():
    out = better_by("a", "b", 3.0, M)(v(a=(1.0, 1.1, float("nan")), b=(5.0, 5.5, 4.5)))
    assert out.verdict == "inconclusive" and "NaN" in out.interval.method and out.interval.seeds == (3, 3)


def test_better_by_not_run_when_a_model_is_missing():
    assert better_by("a", "b", 3.0, M)(v(a=(1.0,))).verdict == "not run"


@pytest.mark.parametrize("values, expected", [
    (dict(a=(1.0, 1.05, 0.95), b=(1.5, 1.4, 1.6)), "reproduced"),
    (dict(a=(1.0, 1.02, 0.98), b=(5.0, 5.1, 4.9)), "not reproduced"),   # a 5x gap is not "similar"
    (dict(a=(1.0, 1.02, 0.98), b=(50.0, 51.0, 49.0)), "not reproduced"),
    (dict(a=(1.0, 1.0), b=(2.0, 4.0)), "inconclusive"),
    (dict(a=(math.inf, math.inf, math.inf), b=(1.0, 1.1, 0.9)), "not reproduced"),
    (dict(a=1.0, b=1.5), "inconclusive"),                               # one seed: no interval
])
def test_similar(values, expected):
    out = similar("a", "b", 3.0, M)(v(**values))
    assert out.verdict == expected, out.reason
    assert set(out.sensitivity) == {"within 1.73205", "within 9"}


def test_similar_names_the_lower_model_when_it_is_far_lower():
    out = similar("lnn", "baseline", 1.5, M)(v(lnn=(1.0, 1.02, 0.98), baseline=(2.8, 2.9, 2.7)))
    assert out.verdict == "not reproduced" and "lnn is lower by more than 1.5x" in out.reason


def _matched(a, b, level_a, level_b):
    return {"a": {M: Stat.of(a), "lvl": Stat.of(level_a)}, "b": {M: Stat.of(b), "lvl": Stat.of(level_b)}}


LV = (0.5, 0.51, 0.49)


@pytest.mark.parametrize("values, expected", [
    (((1.0, 1.1, 0.9), (5.0, 6.0, 5.5), LV, LV), "reproduced"),
    (((1.0, 1.1, 0.9), (5.0, 6.0, 5.5), (0.2, 0.21, 0.19), LV), "inconclusive"),   # a is far more accurate there
    (((1.0, 1.1, 0.9), (5.0, 6.0, 5.5), LV, (0.5, 0.51, math.inf)), "inconclusive"),  # b never got near the level
    (((3.0, 3.1, 2.9), (5.0, 6.0, 5.5), LV, LV), "not reproduced"),
    (((math.inf, 1.0, 1.1), (5.0, 6.0, 5.5), LV, LV), "inconclusive"),  # a diverged once
    (((math.inf,) * 3, (5.0, 6.0, 5.5), LV, LV), "not reproduced"),
    (((0.0, 0.0, 0.0), (5.0, 6.0, 5.5), (40.0, 40.0, 40.0), LV), "inconclusive"),       # a null: never matched
])
def test_matched_better_by_decides_only_at_matched_accuracy(values, expected):
    out = matched_better_by("a", "b", 3.0, M, "lvl", 1.5)(_matched(*values))
    assert out.verdict == expected, out.reason
    assert matched_better_by("a", "b", 3.0, M, "lvl", 1.5)({"a": {M: Stat.of((1.0,))}}).verdict == "not run"


@pytest.mark.parametrize("values, expected", [
    (dict(bad=(40.0, 45.0), g1=(1.0, 1.1), g2=(2.0, 2.1)), "reproduced"),
    (dict(bad=(4.0, 4.5), g1=(1.0, 1.1), g2=(2.0, 2.1)), "not reproduced"),   # the worst, but not by 10x
    (dict(bad=(0.5, 0.6), g1=(1.0, 1.1), g2=(2.0, 2.1)), "not reproduced"),
    (dict(bad=(5.0, 40.0), g1=(1.0, 1.1), g2=(2.0, 2.1)), "inconclusive"),
])
def test_fails(values, expected):
    assert fails("bad", ("g1", "g2"), 10.0, M)(v(**values)).verdict == expected


def test_below_null():
    def vals(x, null):
        return {"a": {M: Stat.of(x), f"null_{M}": Stat.of(null)}}
    assert below_null(M, 0.5, "a")(vals((0.1, 0.12, 0.11), (1.0, 1.0, 1.0))).verdict == "reproduced"
    assert below_null(M, 0.5, "a")(vals((1.0, 0.9), (1.0, 1.0))).verdict == "not reproduced"   # the null itself
    assert below_null(M, 0.5, "a")(vals((0.2, 0.9), (1.0, 1.0))).verdict == "inconclusive"
    assert below_null(M, 0.5, "a")(vals((0.1, 0.2), (1.0, 1.0))).verdict == "inconclusive"   # 2 seeds this far apart
    assert below_null(M, 0.5, "a")({"a": {M: Stat.of((0.1,))}}).verdict == "not run"


def test_never():
    inf = math.inf
    assert never("bad", M)(v(bad=(inf, inf, inf))).verdict == "reproduced"
    out = never("bad", M)(v(bad=(inf, 5e4, inf)))
    assert out.verdict == "not reproduced" and "1/3" in out.reason
    assert never("bad", M)(v(good=(1.0,))).verdict == "not run"


def test_faster_reports_the_direction_with_an_interval():
    inf = math.inf
    fast, slow = tuple(1e4 + i for i in range(8)), tuple(5e4 + i for i in range(8))
    out = faster("a", "b", 3, M)(v(a=fast, b=slow))
    assert out.verdict == "reproduced" and out.interval.hi < 1, out.reason
    out = faster("a", "b", 3, M)(v(a=slow, b=fast))
    assert out.verdict == "not reproduced" and out.interval.lo > 1 and "b faster" in out.reason
    out = faster("a", "b", 3, M)(v(a=(1e4, 1e4) + (inf,) * 6, b=(inf,) * 8))
    assert out.verdict == "inconclusive", out.reason            # two of eight: too few to tell
    assert faster("a", "b", 3, M)(v(a=(inf,) * 8, b=(inf,) * 8)).verdict == "inconclusive"
    assert faster("a", "b", 3, M)(v(a=fast[:3], b=slow[:3])).verdict == "inconclusive"   # 3 seeds never reach it


def test_bound():
    ok, bad = v(a=(0.0, 1e-13)), v(a=(0.0, 1e-3))
    assert bound(M, upper=1e-12)(ok).verdict == "reproduced" and bound(M, upper=1e-12)(bad).verdict == "not reproduced"
    assert bound(M, lower=0.0)(v(a=(0.1, 0.2))).verdict == "reproduced"
    assert bound(M, lower=0.0)(v(a=(0.0, 0.2))).verdict == "not reproduced"
    assert bound(M, upper=1.0)(v(a=math.inf)).verdict == "not reproduced"
    assert bound(M, upper=1.0, models=("b",))(v(a=0.5)).verdict == "not run"


def _with_null(model_values, null=10.0, n_div=None, status=None):
    """One model's seed rows: its metric per seed, the null's beside it, and optionally its diverged count."""
    vals = model_values if isinstance(model_values, tuple) else (model_values,)
    rows = []
    for i, x in enumerate(vals):
        r = {"seed": i, "status": (status or {}).get(i, "ok"), "heldout_l1": x, "null_heldout_l1": null}
        if n_div is not None:
            r["n_diverged"] = n_div
        rows.append(r)
    return rows


def test_bar_passes_a_model_that_learned_and_stops_a_null_or_diverging_one():
    bar = Bar(("a",), "heldout_l1")
    assert bar.check("a", _with_null(0.5))[0]
    assert not bar.check("a", _with_null(10.0))[0]           # the null itself
    assert not bar.check("a", _with_null(math.inf))[0]
    assert not bar.check("a", [{"seed": 0, "status": "ok", "heldout_l1": 0.1}])[0]   # null not recorded: cannot pass
    roll = Bar(("a",), None, max_diverged=0)
    assert roll.check("a", _with_null(0.5, n_div=0))[0]
    assert not roll.check("a", _with_null(0.5, n_div=1))[0]
    assert not roll.check("a", _with_null(0.5))[0]           # divergence not recorded


def test_bar_reads_every_seed_and_a_failed_or_nan_seed_fails_it():
    bar = Bar(("a",), "heldout_l1")
    passed, why, per = bar.check("a", _with_null((0.011, 1.33)))      # a good seed cannot hide one at the null
    assert not passed and [p["passed"] for p in per] == [True, False]
    assert "1/2 seeds" in why and "0.011" in why and "1.33" in why    # every seed's value is shown
    assert not bar.check("a", _with_null((0.5, float("nan"))))[0]
    assert not bar.check("a", _with_null((0.5, 0.5), status={1: "failed"}))[0]
    assert bar.check("a", _with_null((0.5, 0.6)))[0]


def test_competence_all_and_any():
    vals = {"a": _with_null(0.5), "b": _with_null(9.0)}
    ok, why, per = competence((Bar(("a", "b")),), vals)
    assert not ok and "b:" in why[0] and per["a"][0] and not per["b"][0]
    ok, _, _ = competence((Bar(("a", "b"), need="any"),), vals)
    assert ok
    ok, why, _ = competence((Bar(("b",), need="any"),), vals)
    assert not ok and why[0].startswith("none of them passed")


def test_a_model_under_two_bars_passes_only_if_it_passes_both():
    vals = {"a": _with_null(9.0, n_div=0)}
    ok, _, per = competence((Bar(("a",), "heldout_l1"), Bar(("a",), None, max_diverged=0)), vals)
    assert not ok and per["a"][0] is False and per["a"][2][0]["passed"] is False
    assert "9 > 0.1 x null 10" in per["a"][1] and "0 diverged rollouts" in per["a"][1]


@pytest.mark.parametrize("values, expected", [
    (dict(a=(1.0, 2.0, 1.5), b=(3.0, math.inf, 4.0)), "reproduced"),
    (dict(a=(1.0, math.inf, math.inf), b=(math.inf,) * 3), "inconclusive"),   # one seed of a got there
    (dict(a=(math.inf,) * 3, b=(2.0, math.inf, 3.0)), "not reproduced"),
    (dict(a=(math.inf,) * 3, b=(math.inf,) * 3), "inconclusive"),   # never tie, never sooner
    (dict(a=(1.0, 2.0), b=(3.0, math.inf)), "inconclusive"),         # 2 seeds with a never: no exact interval
])
def test_sooner_reads_never_as_inf_and_decides_nothing_when_neither_got_there(values, expected):
    out = sooner("a", "b", M)(v(**values))
    assert out.verdict == expected, out.reason
    assert better_by("a", "b", 1.0, M)(v(a=(math.inf,) * 3, b=(math.inf,) * 3)).verdict == "not reproduced"
    assert sooner("a", "c", M)(v(a=(1.0,))).verdict == "not run"
