"""The verdict vocabulary (`replication.claims.rules`) and the competence bars, on synthetic seed values:
each rule reproduces, half-reproduces, fails, and stays inconclusive where the seed ranges overlap."""
import math

import pytest

from replication.claims.bars import Bar, competence
from replication.claims.rules import (
    Stat,
    all_parts,
    better_by,
    bound,
    fails,
    lowest,
    never,
    separated,
    similar,
)

M = "m"


def v(**models):
    """v(a=(1, 2, 3), b=(4,)) -> {"a": {"m": Stat}, ...}."""
    return {k: {M: Stat.of(x if isinstance(x, tuple) else (x,))} for k, x in models.items()}


def test_stat_counts_a_diverged_seed_as_infinite_and_drops_nan():
    s = Stat.of([1.0, math.inf, float("nan"), None])
    assert s.n == 2 and s.mean == math.inf and s.std == math.inf and s.hi == math.inf
    assert Stat.of([math.inf, math.inf]).std == 0.0
    with pytest.raises(ValueError, match="no finite"):
        Stat.of([float("nan")])


def test_separated_means_no_seed_overlap():
    assert separated(Stat.of([1, 2]), Stat.of([3, 4]))
    assert not separated(Stat.of([1, 3.5]), Stat.of([3, 4]))
    assert separated(Stat.of([1, 2]), Stat.of([3, math.inf]))


@pytest.mark.parametrize("values, expected", [
    (dict(a=(1.0, 1.1, 0.9), b=(5.0, 5.5, 4.5)), "reproduced"),
    (dict(a=(1.0, 1.1, 0.9), b=(2.0, 2.1, 1.9)), "partly"),
    (dict(a=(5.0, 5.5, 4.5), b=(1.0, 1.1, 0.9)), "not reproduced"),
    (dict(a=(1.0, 4.0, 0.5), b=(5.0, 3.0, 6.0)), "inconclusive"),     # mean gap, seeds overlap
    (dict(a=(1.0, 1.1, 0.9), b=(math.inf, 8.0, 9.0)), "reproduced"),  # one diverged seed of b
    (dict(a=(1.0,)), "not run"),
])
def test_better_by(values, expected):
    assert better_by("a", "b", 3.0, M)(v(**values))[0] == expected


@pytest.mark.parametrize("values, expected", [
    (dict(a=1.0, b=1.5), "reproduced"),
    (dict(a=1.0, b=5.0), "partly"),
    (dict(a=1.0, b=50.0), "not reproduced"),
    (dict(a=math.inf, b=1.0), "not reproduced"),
])
def test_similar(values, expected):
    assert similar("a", "b", 3.0, 10.0, M)(v(**values))[0] == expected


@pytest.mark.parametrize("values, expected", [
    (dict(o=(1.0, 1.2), x=(2.0, 2.2), y=(3.0, 3.1)), "reproduced"),
    (dict(o=(1.0, 2.5), x=(2.0, 2.2), y=(3.0, 3.1)), "partly"),
    (dict(o=(3.0, 3.2), x=(2.0, 2.2), y=(1.0, 1.1)), "not reproduced"),
    (dict(o=(1.0, 2.5), x=(2.0, 2.2)), "inconclusive"),
])
def test_lowest(values, expected):
    others = tuple(k for k in values if k != "o")
    assert lowest("o", others, M)(v(**values))[0] == expected


@pytest.mark.parametrize("values, expected", [
    (dict(bad=(40.0, 45.0), g1=(1.0, 1.1), g2=(2.0, 2.1)), "reproduced"),
    (dict(bad=(4.0, 4.5), g1=(1.0, 1.1), g2=(2.0, 2.1)), "partly"),
    (dict(bad=(0.5, 0.6), g1=(1.0, 1.1), g2=(2.0, 2.1)), "not reproduced"),
    (dict(bad=(0.5, 4.0), g1=(1.0, 1.1), g2=(2.0, 2.1)), "inconclusive"),
])
def test_fails(values, expected):
    assert fails("bad", ("g1", "g2"), 10.0, M)(v(**values))[0] == expected


def test_never():
    inf = math.inf
    assert never("bad", M)(v(bad=(inf, inf, inf)))[0] == "reproduced"
    verdict, reason = never("bad", M)(v(bad=(inf, 5e4, inf)))
    assert verdict == "not reproduced" and "1/3" in reason
    assert never("bad", M)(v(good=(1.0,)))[0] == "not run"


def test_bound_and_all_parts():
    ok, bad = v(a=(0.0, 1e-13)), v(a=(0.0, 1e-3))
    assert bound(M, upper=1e-12)(ok)[0] == "reproduced" and bound(M, upper=1e-12)(bad)[0] == "not reproduced"
    assert bound(M, lower=0.0)(v(a=(0.1, 0.2)))[0] == "reproduced"
    assert bound(M, lower=0.0)(v(a=(0.0, 0.2)))[0] == "not reproduced"
    assert bound(M, upper=1.0)(v(a=math.inf))[0] == "not reproduced"
    yes, no, unsure = (lambda x: ("reproduced", "")), (lambda x: ("not reproduced", "")), (lambda x: ("inconclusive", ""))
    assert all_parts(yes, yes)({})[0] == "reproduced"
    assert all_parts(yes, no)({})[0] == "partly"
    assert all_parts(no, no)({})[0] == "not reproduced"
    assert all_parts(yes, unsure)({})[0] == "inconclusive"


def _with_null(model_value, null=10.0, n_div=None):
    s = {"heldout_l1": Stat.of([model_value]), "null_heldout_l1": Stat.of([null])}
    if n_div is not None:
        s["n_diverged"] = Stat.of([n_div])
    return s


def test_bar_passes_a_model_that_learned_and_stops_a_null_or_diverging_one():
    bar = Bar(("a",), "heldout_l1")
    assert bar.check("a", _with_null(0.5))[0]
    assert not bar.check("a", _with_null(10.0))[0]           # the null itself
    assert not bar.check("a", _with_null(math.inf))[0]
    assert not bar.check("a", {"heldout_l1": Stat.of([0.1])})[0]   # null not recorded: cannot pass
    roll = Bar(("a",), None, max_diverged=0)
    assert roll.check("a", _with_null(0.5, n_div=0))[0]
    assert not roll.check("a", _with_null(0.5, n_div=1))[0]
    assert not roll.check("a", _with_null(0.5))[0]           # divergence not recorded


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
    assert not ok and per["a"][0] is False
    assert "heldout_l1 9 > 0.1 x null 10" in per["a"][1] and "0 diverged rollouts" in per["a"][1]
