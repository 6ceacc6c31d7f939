"""Hard cases: training blow-ups are caught at the step, indefinite Hessians are counted, the
relativistic particle near the speed of light, the chaos floor beside every rollout metric."""
import numpy as np
import pytest

from lagbench import systems
from lagbench.models import ModelSpec, init_params
from lagbench.replication.training import hessian_probe
from lagbench.replication.training.protocol import Data, Protocol
from lagbench.replication.training.schedules import Constant
from lagbench.replication.training.train import run_training


@pytest.mark.parametrize("framework", ["jax", "torch"])
def test_blow_up_is_caught_at_its_step_and_keeps_the_last_good_parameters(framework):
    spec = ModelSpec(kind="baseline", dof=2, hidden=(8,), activation="relu", init="xavier")
    p = Protocol(data=Data("double_pendulum_iid", n_train=80), steps=10, batch=8, log_every=1, schedule=Constant(lr=1e30))
    o = run_training(framework, spec, p, seed=0)
    assert o.failure is not None and o.failure["kind"].startswith("non_finite")
    k = o.failure["step"]
    assert 0 < k < 10 and f"step {k}" in o.failure["message"] and o.steps_done == k
    assert all(np.all(np.isfinite(v)) for v in o.params.values()), "the kept parameters must be the last good ones"


def test_fresh_lnn_has_indefinite_velocity_hessians_and_says_so():
    """The reference measured 42 % indefinite at the empirical init (4-600-600-600-1, training states)."""
    import jax.numpy as jnp

    import lagbench.models.jax

    spec = ModelSpec(kind="lnn", dof=2, hidden=(600, 600, 600), dtype="float64", angle_wrap=True)
    m = lagbench.models.jax.build(spec, init_params(spec, seed=0))
    st = systems.get("double_pendulum").sample_states(2000, np.random.default_rng(0))
    H = np.asarray(m.velocity_hessian(jnp.asarray(st["q"]), jnp.asarray(st["qdot"])))
    eig = np.linalg.eigvalsh(H)
    indefinite = np.mean((eig[:, 0] < 0) & (eig[:, -1] > 0))
    assert 0.25 < indefinite < 0.6, indefinite
    qdd, n_fb = m.acceleration_info(jnp.asarray(st["q"]), jnp.asarray(st["qdot"]))
    assert np.all(np.isfinite(np.asarray(qdd)))  # indefinite is not singular: solved, not silently NaN


def test_probe_tells_indefinite_from_singular():
    hess = np.array([np.diag([1.0, 2.0]), np.diag([-1.0, 2.0]), np.diag([1e-9, 1.0])])
    row = hessian_probe.probe(np.array([[1.0, -7.0]] * 3), 2, hess, "float32")
    assert row == {"hessian_fallbacks": 2, "qddot_max_abs": 7.0, "hessian_indefinite_fraction": 1 / 3,
                   "hessian_singular_fraction": 1 / 3}
    summary = hessian_probe.summarize([row, {**row, "hessian_fallbacks": 1}])
    assert summary["train_hessian_fallbacks_total"] == 3 and summary["train_hessian_indefinite_fraction_max"] == 1 / 3


def test_training_logs_the_hessian_health_alike_in_both_frameworks():
    """Float64, same init and batches: the probe sees the same Hessians in JAX and PyTorch at every
    logged step, and the fraction is the measured one of a freshly initialised LNN (well above 0)."""
    spec = ModelSpec(kind="lnn", dof=2, hidden=(64, 64), dtype="float64", angle_wrap=True)
    p = Protocol(data=Data("double_pendulum_iid", n_train=640), steps=6, batch=64, log_every=2, dtype="float64", schedule=Constant(lr=1e-3))
    logs = {fw: run_training(fw, spec, p, seed=0).log for fw in ("jax", "torch")}
    for col in hessian_probe.COLUMNS:
        a, b = [np.array([r[col] for r in logs[fw]]) for fw in ("jax", "torch")]
        np.testing.assert_allclose(a, b, rtol=1e-6, err_msg=col)
    frac = [r["hessian_indefinite_fraction"] for r in logs["jax"]]
    assert len(frac) == 4 and all(0.0 < f <= 1.0 for f in frac), frac


@pytest.mark.parametrize("dtype, rtol", [(np.float64, 1e-9), (np.float32, 2e-3)])
@pytest.mark.parametrize("name, law", [
    ("relativistic", lambda v, g: g * (1 - v**2) ** 2.5 / (1 + 2 * v**2)),
    ("relativistic_standard", lambda v, g: g * (1 - v**2) ** 1.5),
])
def test_relativistic_accelerations_near_the_speed_of_light(name, law, dtype, rtol):
    s = systems.get(name, g=9.8)
    v = np.array([0.9, 0.99, 0.999, 0.9999, -0.99999])[:, None].astype(dtype)
    q = np.zeros_like(v)
    got = s.acceleration(q, v, backend="numpy")
    want = law(v.astype(np.float64), 9.8)
    assert got.dtype == dtype
    np.testing.assert_allclose(got.astype(np.float64), want, rtol=rtol)
    with pytest.raises(ValueError):
        s.acceleration(q, np.ones_like(v), backend="numpy")


def test_energy_metrics_come_with_the_chaos_floor(smoke_results):
    import pandas as pd

    out, _ = smoke_results
    units = pd.read_csv(out / "summary" / "units.csv")
    dp = units[units["claim"] == "dp_energy"]
    assert len(dp) and dp["chaos_floor_gmean_err"].notna().all() and (dp["chaos_floor_gmean_err"] > 0).all()
