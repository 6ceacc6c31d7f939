"""Property-based tests of the public API: random shapes, dtypes and values (NaN, inf, negative sizes,
empty arrays) give either a correct result or a clean ValueError / TypeError / KeyError with a message."""
import math
import uuid
from functools import partial

import numpy as np
import pandas as pd
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from lagbench import systems
from lagbench.files import user_data
from lagbench.replication.evaluation import metrics
from lagbench.replication.training.protocol import Data, Protocol
from lagbench.replication.training.schedules import SCHEDULES, Constant, OneCycle, StepDecay, learning_rate

CLEAN = (ValueError, TypeError, KeyError)
# no subnormal floats: once lagbench's PyTorch is imported the process's threads flush them to zero
# (`models.torch.subnormals`), and Hypothesis refuses to draw what the CPU cannot represent
floats = partial(st.floats, allow_subnormal=False)
FAST = settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])

weird_numbers = st.one_of(st.integers(-5, 10**6), floats(allow_nan=True, allow_infinity=True),
                          st.just(None), st.text(max_size=3))


def _clean(err):
    assert isinstance(err, CLEAN), f"{type(err).__name__}: {err}"
    assert str(err), f"{type(err).__name__} without a message"


# --- Protocol -----------------------------------------------------------------------------------------

@FAST
@given(steps=weird_numbers, batch=weird_numbers, n_train=weird_numbers, lr=weird_numbers,
       dtype=st.sampled_from(["float32", "float64", "float16", "", "int8"]),
       schedule=st.sampled_from(["constant", "step", "onecycle", "cosine"]), every=weird_numbers)
def test_protocol_is_valid_or_rejected_cleanly(steps, batch, n_train, lr, dtype, schedule, every):
    try:
        sched = SCHEDULES[schedule](**{"lr": lr, **({"every": every, "gamma": 0.1} if schedule == "step" else {})})
        p = Protocol(data=Data("spring_iid", n_train=n_train), steps=steps, batch=batch, dtype=dtype, schedule=sched)
    except Exception as e:  # noqa: BLE001 - the property is the exception's type and message
        _clean(e)
        return
    assert int(p.steps) >= 1 and 1 <= int(p.batch) <= int(p.data.n_train)
    assert math.isfinite(p.schedule.lr) and p.schedule.lr > 0 and p.dtype in ("float32", "float64")
    assert Protocol.from_dict(p.to_dict()) == p


@pytest.mark.parametrize("field, value", [("steps", math.inf), ("steps", math.nan), ("steps", 2.5), ("batch", None),
                                          ("schedule.lr", math.inf), ("schedule.lr", math.nan), ("schedule.lr", "1e-3"),
                                          ("log_every", -1), ("data.n_heldout", True), ("data.n_train", 0.5)])
def test_protocol_rejects_non_finite_or_non_integer_fields(field, value):
    ok = Protocol(data=Data("spring_iid", n_train=4), steps=10, batch=1)
    with pytest.raises(ValueError, match="learning rate" if field == "schedule.lr" else field.split(".")[-1]):
        ok.replace(**{field: value})
    with pytest.raises(ValueError, match="step schedule every"):
        StepDecay(lr=1e-3, every=0, gamma=0.1)


# --- learning-rate schedules --------------------------------------------------------------------------

@FAST
@given(lr=floats(1e-8, 10.0), steps=st.integers(1, 5000), schedule=st.sampled_from(["constant", "step",
                                                                                        "onecycle"]),
       gamma=floats(1e-3, 1.0), every=st.integers(1, 3000), start=floats(0.0, 1.0, exclude_max=True),
       ratio=floats(0.0, 1.0), frac=st.lists(floats(0.0, 1.0), min_size=2, max_size=8))
def test_schedules_are_finite_bounded_pure_functions_of_the_step(lr, steps, schedule, gamma, every, start, ratio,
                                                                 frac):
    sched = {"constant": Constant(lr=lr), "step": StepDecay(lr=lr, every=every, gamma=gamma),
             "onecycle": OneCycle(lr=lr, start=start, min_ratio=ratio)}[schedule]
    p = Protocol(data=Data("spring_iid", n_train=1), steps=steps, batch=1, schedule=sched)
    ks = sorted({int(round(f * steps)) for f in frac})
    vals = [learning_rate(p, k) for k in ks]
    assert vals == [learning_rate(p, k) for k in ks]            # pure: same step, same float
    for v in vals:
        assert math.isfinite(v) and 0 <= v <= lr * (1 + 1e-12)
    if schedule == "constant":
        assert all(v == lr for v in vals)
    if schedule == "step":                                         # never increases
        assert all(a >= b for a, b in zip(vals, vals[1:], strict=False))
    if schedule == "onecycle":
        assert all(v >= lr * ratio * (1 - 1e-12) for v in vals)


@FAST
@given(step=st.one_of(st.integers(max_value=-1), floats(allow_nan=True, allow_infinity=True).filter(
    lambda x: not (math.isfinite(x) and x >= 0))))
def test_schedule_rejects_negative_or_non_finite_steps(step):
    p = Protocol(data=Data("spring_iid", n_train=1), steps=10, batch=1, schedule=StepDecay(lr=1e-3, every=1000, gamma=0.1))
    with pytest.raises(ValueError, match="step"):
        learning_rate(p, step)


# --- users' data files --------------------------------------------------------------------------------

arrays = st.builds(lambda n, d, fill, rng: np.random.default_rng(rng).normal(size=(n, d)) if fill is None
                   else np.full((n, d), fill),
                   st.integers(0, 40), st.integers(1, 3), st.one_of(st.none(), st.sampled_from([np.nan, np.inf])),
                   st.integers(0, 10**6))


@FAST
@given(data=st.dictionaries(st.sampled_from(["q", "qdot", "qddot", "tau", "other"]), arrays, max_size=5),
       suffix=st.sampled_from([".npz", ".csv"]))
def test_user_data_loads_or_names_the_problem(tmp_path, data, suffix):
    path = tmp_path / f"{uuid.uuid4().hex}{suffix}"
    if suffix == ".npz":
        np.savez(path, **data)
    else:
        cols = {f"{k}{j}": pd.Series(v[:, j]) for k, v in data.items() for j in range(v.shape[1])}
        pd.DataFrame(cols).to_csv(path, index=False)
    try:
        d = user_data.load(str(path))
    except Exception as e:  # noqa: BLE001
        _clean(e)
        assert str(path) in str(e)
        return
    assert set(user_data.REQUIRED) <= set(d)
    shapes = {v.shape for v in d.values()}
    assert len(shapes) == 1 and next(iter(shapes))[0] >= 20
    assert all(np.all(np.isfinite(v)) for v in d.values())


def test_user_data_with_text_in_a_column(tmp_path):
    path = tmp_path / "text.csv"
    pd.DataFrame({"q0": ["a"] * 30, "qdot0": np.ones(30), "qddot0": np.ones(30)}).to_csv(path, index=False)
    with pytest.raises(ValueError, match="q0"):
        user_data.load(str(path))


# --- metrics ------------------------------------------------------------------------------------------

shapes = st.lists(st.integers(0, 4), min_size=0, max_size=3).map(tuple)
values = st.sampled_from([0.0, 1.0, -2.5, np.nan, np.inf, 1e300])


@FAST
@given(sa=shapes, sb=shapes, va=values, vb=values, dtype=st.sampled_from([np.float32, np.float64, np.int64]))
def test_metrics_give_results_or_clean_errors(sa, sb, va, vb, dtype):
    def make(shape, v):   # int64 cannot hold NaN, inf or 1e300: use 1 there
        with np.errstate(all="ignore"):
            return np.full(shape, v).astype(dtype) if dtype != np.int64 or abs(v) < 1e18 else np.full(shape, 1, dtype)

    a, b = make(sa, va), make(sb, vb)
    for fn, args in ((metrics.heldout_errors, (a, b)), (metrics.bounded_relative_error, (a, b)),
                     (metrics.geometric_mean_over_time, (a,)), (metrics.energy_errors, (a, b, 29.4))):
        try:
            with np.errstate(all="ignore"):
                out = fn(*args)
        except Exception as e:  # noqa: BLE001
            _clean(e)
            continue
        if fn is metrics.bounded_relative_error:
            assert np.all((out >= 0) & (out <= 1))
        if fn is metrics.geometric_mean_over_time:
            assert out.shape == a.shape[:1]


@FAST
@given(n=st.integers(1, 5), t=st.integers(2, 6), seed=st.integers(0, 1000))
def test_metrics_on_valid_trajectories(n, t, seed):
    rng = np.random.default_rng(seed)
    z, zh = rng.normal(size=(n, t, 3)), rng.normal(size=(n, t, 3))
    err = metrics.bounded_relative_error(zh, z)
    assert err.shape == (n, t) and np.all((err >= 0) & (err <= 1))
    np.testing.assert_array_equal(metrics.bounded_relative_error(z, z), 0.0)
    g = metrics.geometric_mean_over_time(err)
    assert g.shape == (n,) and np.all(g <= err[:, 1:].max(1) + 1e-15)
    e = metrics.energy_errors(z[..., 0], z[..., 0], 29.4)
    assert e["energy_err_final"] == 0 and e["n_diverged"] == 0
    h = metrics.heldout_errors(zh[:, 0], z[:, 0])
    assert h["l1"] >= 0 and h["mse"] >= 0


# --- systems with non-physical parameters -------------------------------------------------------------

@settings(max_examples=40, deadline=None)
@given(name=st.sampled_from(["double_pendulum", "spring", "pendulum", "stiff_chain", "two_link_arm"]),
       value=st.one_of(floats(allow_nan=True, allow_infinity=True), st.integers(-3, 3), st.none(),
                       st.text(max_size=2), st.just([1.0, -1.0]), st.just(np.array([]))),
       which=st.integers(0, 10))
def test_system_parameters_valid_or_rejected_cleanly(name, value, which):
    params = sorted(systems.definition(name).params) + ["not_a_parameter"]
    key = params[which % len(params)]
    try:
        s = systems.get(name, **{key: value})
    except Exception as e:  # noqa: BLE001
        _clean(e)
        return
    v = np.asarray(s.params[key], dtype=float)
    assert np.all(np.isfinite(v))
    constraint = systems.definition(name).params[key][2]
    if constraint == "positive":
        assert np.all(v > 0)
    if constraint == "nonnegative":
        assert np.all(v >= 0)
