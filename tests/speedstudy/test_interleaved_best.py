"""Interleaved timing rounds (the scaling study's sizes, the roofline's three) and the scaling groups;
no timing asserted: calls are counted."""
from lagbench.speedstudy.scaling import scaling_groups
from lagbench.speedstudy.timing import LONG_CALL_S, interleaved_best


def _counting(names):
    calls = {k: 0 for k in names}

    def make(k):
        def fn():
            calls[k] += 1
        return fn
    return {k: make(k) for k in names}, calls


def test_every_size_is_called_once_per_round_and_a_long_first_call_sits_out():
    fns, calls = _counting(["n16", "n64", "n1024"])
    best = interleaved_best(fns, first={"n16": 0.0, "n1024": LONG_CALL_S + 1.0})
    assert calls == {"n16": 2, "n64": 2, "n1024": 0}  # at least two rounds; the long one is not repeated
    assert best["n1024"] == LONG_CALL_S + 1.0 and 0 <= best["n16"] < LONG_CALL_S


def test_rounds_stop_at_max_rounds_within_budget():
    fns, calls = _counting(["a", "b"])
    interleaved_best(fns, budget_s=1e9, max_rounds=7)
    assert calls == {"a": 7, "b": 7}


def test_min_rounds_without_budget_is_exactly_that_many():
    fns, calls = _counting(["paper", "fast", "matmul"])
    interleaved_best(fns, min_rounds=4)
    assert calls == {"paper": 4, "fast": 4, "matmul": 4}


def test_groups_keep_study_formulation_and_framework_together():
    cases = [("lgn_grid", "dense", "jax", 16, 64), ("lgn_grid", "dense", "torch", 16, 64),
             ("lgn_grid", "dense", "jax", 64, 16), ("lnn_chain", "fast", "jax", 1, 256)]
    assert scaling_groups(cases) == [[cases[0], cases[2]], [cases[1]], [cases[3]]]
