"""models.jax.compiled.compile_single: the compiled callable gives the model method's numbers (float64,
1e-12), for single samples and a fixed batch, with parameters as arguments or frozen, and refuses what
it cannot compile."""
import numpy as np
import pytest

import lagbench.models.jax
from lagbench.models import ModelSpec, init_params
from lagbench.models.jax.compiled import async_dispatch, compile_single, use_sync_dispatch

RNG = np.random.default_rng(0)


def _model(kind="delan", dtype="float64", **kw):
    spec = ModelSpec(kind=kind, dof=2, hidden=(16, 16), dtype=dtype, init="xavier", **kw)
    return lagbench.models.jax.build(spec, init_params(spec, seed=1))


@pytest.mark.parametrize("method,n,freeze", [("inverse_dynamics", 3, False), ("inverse_dynamics", 3, True),
                                             ("acceleration", 2, False), ("acceleration", 2, True),
                                             ("mass_matrix", 1, False)])
def test_delan_single_sample_matches_method(method, n, freeze):
    m = _model()
    f = compile_single(m, method, freeze=freeze)
    for _ in range(3):
        xs = [RNG.uniform(-2, 2, 2) for _ in range(n)]
        want = np.asarray(getattr(m, method)(*[np.asarray(x) for x in xs]))
        got = np.asarray(f(*xs))
        assert got.shape == want.shape
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-12)


def test_batch_and_tau_input_and_lnn():
    m = _model()
    f = compile_single(m, "acceleration", batch=5, n_inputs=3)
    q, qd, tau = (RNG.uniform(-1, 1, (5, 2)) for _ in range(3))
    np.testing.assert_allclose(np.asarray(f(q, qd, tau)), np.asarray(m.acceleration(q, qd, tau)), rtol=0, atol=1e-12)
    lnn = _model("lnn", angle_wrap=True)
    g = compile_single(lnn, "acceleration")
    q, qd = RNG.uniform(-1, 1, 2), RNG.uniform(-1, 1, 2)
    np.testing.assert_allclose(np.asarray(g(q, qd)), np.asarray(lnn.acceleration(q, qd)), rtol=0, atol=1e-12)


def test_dtype_cast_and_errors():
    m = _model()
    f = compile_single(m, "inverse_dynamics", dtype="float32")
    x = RNG.uniform(-1, 1, 2).astype(np.float32)
    out = f(x, x, x)
    assert out.dtype == np.float32
    np.testing.assert_allclose(np.asarray(out), np.asarray(m.inverse_dynamics(*(x.astype(np.float64),) * 3)),
                               rtol=1e-4, atol=1e-4)
    with pytest.raises(ValueError, match="no method"):
        compile_single(m, "nonexistent")
    with pytest.raises(TypeError):
        f(np.zeros(3, np.float32), x, x)  # wrong shape for the compiled program


def test_sync_dispatch_is_reported():
    # in a test session JAX has started: use_sync_dispatch cannot switch, and says so truthfully
    assert use_sync_dispatch() == (not async_dispatch())
