"""Rollouts in the model's framework (`replication.evaluation.rollout_native`) are the NumPy rollout
(`rollout.rollout` over the adapter's field) to float rounding: for each field (an LNN's acceleration, an
HNN's own flow, DeLaN under interpolated torques), on a grid with uneven intervals, in float64 models so that
rounding is all that may differ; a diverging row is frozen at NaN at the same times; a PyTorch rollout long
enough to compile its step gives the eager numbers (`tox -e slow`)."""
import numpy as np
import pytest

from lagbench.models import ModelSpec, init_params
from lagbench.replication.evaluation import rollout_native as native
from lagbench.replication.evaluation.adapters import adapter
from lagbench.replication.evaluation.rollout import hamiltonian_field, lagrangian_field, rollout

T = np.concatenate([np.linspace(0.0, 0.3, 7), [0.37, 0.41, 0.6]])   # uneven: 1, 2 and 4 steps an interval
DT = 0.05


def _spec(kind):
    extra = {"delan_eps": 0.01, "delan_diag_offset": 2.0} if kind == "delan" else {}
    return ModelSpec(kind=kind, dof=2, hidden=(16, 16), activation="softplus", dtype="float64", **extra)


def _reference(view, kind, z0, tau):
    """The NumPy rollout of the same model: tau interpolated per row by np.interp on the time in the state."""
    if kind == "hnn":
        return rollout(hamiltonian_field(lambda x, y: view.time_derivative(x, y, None), 2), z0, T, DT)
    if tau is None:
        return rollout(lagrangian_field(lambda q, v: view.acceleration(q, v, None), 2), z0, T, DT)

    def f(z):
        u = np.stack([[np.interp(z[i, -1], T - T[0], tau[i][:, j]) for j in range(2)] for i in range(len(z))])
        return np.concatenate([z[:, 2:4], view.acceleration(z[:, :2], z[:, 2:4], u), np.ones((len(z), 1))], 1)
    return rollout(f, np.concatenate([z0, np.zeros((len(z0), 1))], 1), T, DT)[..., :4]


@pytest.mark.parametrize("framework", ["jax", "torch"])
@pytest.mark.parametrize("kind", ["lnn", "hnn", "delan"])
def test_native_rollout_is_the_numpy_rollout(framework, kind):
    spec = _spec(kind)
    view = adapter(framework, spec, init_params(spec, seed=1))
    rng = np.random.default_rng(0)
    z0 = rng.normal(scale=0.5, size=(3, 4))
    tau = rng.normal(size=(3, T.size, 2)) if kind == "delan" else None
    field = "time_derivative" if kind == "hnn" else "acceleration"
    done = []
    z = native.native_rollout(framework, view.model, "float64", field, z0, T, DT, forcing=tau, progress=done.append)
    ref = _reference(view, kind, z0, tau)
    assert z.shape == ref.shape == (3, T.size, 4) and np.isfinite(ref).all()
    np.testing.assert_allclose(z, ref, rtol=1e-9, atol=1e-11)
    assert done[-1] == T.size - 1


def test_plan_splits_intervals_as_the_numpy_rollout():
    n, h = native.plan(T, DT)
    assert n.tolist() == [1] * 6 + [2, 1, 4]
    np.testing.assert_allclose(n * h, np.diff(T), rtol=1e-15)


class _Blowup:
    """qddot = 50 q^3: a row starting far enough out diverges within the grid, the others stay finite."""
    spec = None

    def acceleration(self, q, v, tau):
        return 50.0 * q ** 3


@pytest.mark.parametrize("framework", ["jax", "torch"])
def test_a_diverging_row_is_nan_from_then_on_as_in_the_numpy_rollout(framework):
    z0 = np.array([[0.1, 0.0, 0.0, 0.0], [3.0, 0.1, 0.0, 0.0]])
    t = np.linspace(0.0, 2.0, 21)
    ref = rollout(lagrangian_field(lambda q, v: 50.0 * q ** 3, 2), z0, t, 0.05)
    z = native.native_rollout(framework, _Blowup(), "float64", "acceleration", z0, t, 0.05)
    assert np.isfinite(ref[0]).all() and np.isnan(ref[1, -1]).all()   # the case is what it claims
    np.testing.assert_array_equal(np.isnan(z), np.isnan(ref))
    np.testing.assert_allclose(z[0], ref[0], rtol=1e-12)


@pytest.mark.slow   # slow: 30-50 s building the step's library; building such libraries (`compile_batched`) stays in the default run
def test_a_long_torch_rollout_compiles_its_step_and_gives_the_eager_numbers(monkeypatch):
    spec = _spec("delan")
    view = adapter("torch", spec, init_params(spec, seed=1))
    rng = np.random.default_rng(3)
    z0, tau = rng.normal(scale=0.5, size=(2, 4)), rng.normal(size=(2, T.size, 2))
    eager = native.native_rollout("torch", view.model, "float64", "acceleration", z0, T, DT, forcing=tau)
    built = []
    compiled = native._compiled
    monkeypatch.setattr(native, "_compiled", lambda *a: built.append(compiled(*a)) or built[-1])
    monkeypatch.setattr(native, "COMPILE_CALLS", 1)
    z = native.native_rollout("torch", view.model, "float64", "acceleration", z0, T, DT, forcing=tau)
    assert built and built[0] is not None   # the compiled step ran
    np.testing.assert_allclose(z, eager, rtol=1e-9, atol=1e-11)


def test_a_torch_delan_whose_solve_fails_on_a_diverging_row_marks_that_row_diverged():
    """This DeLaN under these torques drives its second row to a singular mass matrix, where
    torch.linalg.solve raises: that row is NaN from then on, the first is the one-row rollout's (to rounding)."""
    spec = _spec("delan")
    view = adapter("torch", spec, init_params(spec, seed=2))
    rng = np.random.default_rng(3)
    z0, tau = rng.normal(scale=0.5, size=(2, 4)), rng.normal(size=(2, T.size, 2))
    z = native.native_rollout("torch", view.model, "float64", "acceleration", z0, T, DT, forcing=tau)
    alone = native.native_rollout("torch", view.model, "float64", "acceleration", z0[:1], T, DT, forcing=tau[:1])
    assert np.isnan(z[1, -1]).all() and np.isfinite(z[0]).all()
    np.testing.assert_allclose(z[0], alone[0], rtol=1e-9)   # batch sizes round apart only
