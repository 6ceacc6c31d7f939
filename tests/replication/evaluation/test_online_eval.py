"""Claim 13's evaluation (`replication.evaluation.online_claim`): a fixed zero model is PD alone and fails the
competence bar, a diverging one is counted diverged and fails it, a feed-forward net learning online in either
framework gets below PD alone and crosses the threshold (but never reaches it held 5 s in a 1 s run), a window
with a diverged tick never counts as at the threshold, and the test split learns on other references."""
import math
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from lagbench.models import ModelSpec
from lagbench.replication.claims import get
from lagbench.replication.claims.bars import competence
from lagbench.replication.evaluation.online_claim import _windows, eval_online
from lagbench.replication.run.splits import DEV, TEST

CFG = {"seconds": 1.0, "window": 0.5, "n_unseen": 1, "unseen_duration": 0.4}
SPECS = {"delan": ModelSpec(dof=2, hidden=(16, 16), kind="delan", activation="softplus", init="xavier"),
         "ff": ModelSpec(dof=2, hidden=(16, 16), kind="baseline", activation="softplus", init="xavier", extra_inputs=2)}


class Fixed:
    """A model that does not learn, giving the torque fn(q, qdot, qddot) as either kind's method."""

    def __init__(self, fn):
        self.fn = fn

    def inverse_dynamics(self, q, qdot, qddot):
        return self.fn(q, qdot, qddot)

    def acceleration(self, q, qdot, extra):
        return self.fn(q, qdot, extra)


def Zero():
    return Fixed(lambda q, v, a: np.zeros_like(q))


def Diverging():
    return Fixed(lambda q, v, a: 1e9 * np.ones_like(q))


def _evaluate(label="ff", model=None, framework="torch", split=DEV, seed=0):
    ctx = SimpleNamespace(cfg=CFG, model=model, spec=SPECS[label], framework=framework, seed=seed, split=split,
                          protocol=get("delan_online").protocol("smoke"), progress=None)
    with np.errstate(all="ignore"):
        return eval_online(ctx)


def _bar_passes(metrics) -> bool:
    row = [{"seed": 0, "status": "ok", **metrics}]
    ok, _, per = competence(get("delan_online").bars, {"delan": row, "ff": row})
    return ok


def test_a_zero_model_is_pd_alone_never_reaches_the_threshold_and_fails_the_bar():
    m = _evaluate("delan", Zero()).metrics
    assert m["final_window_mse"] == pytest.approx(m["null_final_window_mse"], rel=1e-12)
    assert m["tail_mse"] == pytest.approx(m["null_tail_mse"], rel=1e-12)
    assert m["unseen_mse"] == pytest.approx(m["null_unseen_mse"], rel=1e-12)
    assert math.isinf(m["t_reach_s"]) and math.isinf(m["t_first_cross_s"]) and math.isinf(m["t_settle_s"])
    assert m["steps"] == 0 and m["n_diverged"] == 0
    assert not _bar_passes(m)


def test_a_diverging_model_is_counted_and_fails_the_bar():
    m = _evaluate("ff", Diverging()).metrics
    assert m["n_diverged"] > 0 and math.isinf(m["unseen_mse"]) and math.isinf(m["t_reach_s"])
    assert math.isinf(m["final_window_mse"]) and math.isinf(m["tail_mse"]) and m["n_diverged_ticks"] > 0
    assert not _bar_passes(m)


@pytest.mark.parametrize("framework", ["jax", "torch"])
def test_a_feed_forward_net_learning_online_gets_below_pd_alone(framework):
    ev = _evaluate("ff", framework=framework)
    m = ev.metrics
    assert m["steps"] == 500 and m["n_diverged"] == 0 and m["compute_us_mean"] > 0
    assert m["final_window_mse"] < 0.1 * m["null_final_window_mse"] and m["t_first_cross_s"] <= 1.0 + 1e-9
    assert math.isinf(m["t_reach_s"])   # 1 s of windows cannot hold the bar for the claim's 5 s
    assert _bar_passes(m)
    assert list(ev.arrays["window_end"]) == [0.5, 1.0]
    assert np.allclose(ev.arrays["window_ratio"], ev.arrays["window_mse"] / ev.arrays["pd_window_mse"])


def test_a_window_with_a_diverged_tick_is_infinite_and_never_at_the_threshold():
    pd_w = pd.DataFrame({"t_start": [0.0, 0.5], "track_mse": [1.0, 1.0]})
    w = _windows([{"t_start": 0.0, "track_mse": 0.0, "n_diverged": 49, "steps": 0},
                  {"t_start": 0.5, "track_mse": 0.01, "n_diverged": 0, "steps": 0}], pd_w)
    assert list(w["ratio_to_pd"]) == [math.inf, 0.01]


def test_the_test_split_learns_on_other_references():
    a = _evaluate("ff", Zero()).metrics
    b = _evaluate("ff", Zero(), split=TEST).metrics
    assert a["null_final_window_mse"] != b["null_final_window_mse"] and a["null_unseen_mse"] != b["null_unseen_mse"]
