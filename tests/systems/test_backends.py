"""NumPy, JAX and PyTorch callables agree (float64 to 1e-12) and keep the input dtype."""

import jax.numpy as jnp
import numpy as np
import pytest
import torch

from lagbench import systems

CASES = [(n, {}) for n in systems.names()] + [("wave", {"variant": "textbook", "n": 12}),
                                               ("pendulum_chain", {"n": 4})]


def _methods(s):
    out = ["acceleration", "energy", "canonical_momentum", "canonical_momentum_rate", "velocity_hessian",
           "inverse_dynamics"]
    if s.structure["quadratic_kinetic"]:
        out += ["mass_matrix", "gravity", "coriolis", "coriolis_matrix"]
    return out


def _call(s, method, backend, conv, st, extra):
    q, qdot = conv(st["q"]), conv(st["qdot"])
    kw = {k: conv(v) for k, v in extra.items()}
    if method in ("mass_matrix", "gravity"):
        return getattr(s, method)(q, backend=backend, **kw)
    if method == "inverse_dynamics":
        return s.inverse_dynamics(q, qdot, conv(st["qddot"]), backend=backend, **kw)
    return getattr(s, method)(q, qdot, backend=backend, **kw)


@pytest.mark.parametrize("name,opts", CASES, ids=[f"{n}{o}" for n, o in CASES])
def test_backends_agree_in_float64(name, opts):
    s = systems.get(name, **opts)
    st = s.sample_states(64, 0)
    extra = {k: v for k, v in st.items() if k not in ("q", "qdot")}
    st["qddot"] = np.random.default_rng(2).normal(size=st["q"].shape)
    for method in _methods(s):
        ref = _call(s, method, "numpy", np.asarray, st, extra)
        assert ref.dtype == np.float64
        j = _call(s, method, "jax", jnp.asarray, st, extra)
        t = _call(s, method, "torch", torch.as_tensor, st, extra)
        assert isinstance(j, jnp.ndarray) and j.dtype == jnp.float64
        assert isinstance(t, torch.Tensor) and t.dtype == torch.float64
        scale = max(1.0, np.abs(ref).max())
        np.testing.assert_allclose(np.asarray(j), ref, rtol=1e-12, atol=1e-12 * scale, err_msg=method)
        np.testing.assert_allclose(t.numpy(), ref, rtol=1e-12, atol=1e-12 * scale, err_msg=method)


@pytest.mark.parametrize("backend,conv", [("numpy", lambda x: np.asarray(x, np.float32)),
                                          ("jax", lambda x: jnp.asarray(x, jnp.float32)),
                                          ("torch", lambda x: torch.as_tensor(x, dtype=torch.float32))])
def test_float32_stays_float32(backend, conv):
    s = systems.get("relativistic")
    st = s.sample_states(8, 0)
    out = s.acceleration(conv(st["q"]), conv(st["qdot"]), backend=backend, g=conv(st["g"]))
    assert str(out.dtype).endswith("float32")
    ref = s.acceleration(st["q"], st["qdot"], g=st["g"])
    np.testing.assert_allclose(np.asarray(out), ref, rtol=1e-3, atol=1e-4)


F32 = (np.zeros(2, np.float32), np.float32(1.0), jnp.zeros(2, jnp.float32), torch.zeros(2))
F64_OR_OTHER = (np.zeros(2), 1.0, [1.0, 2.0], jnp.zeros(2), torch.zeros(2, dtype=torch.float64),
                torch.zeros(2, dtype=torch.float16), np.zeros(2, np.int64), np.zeros(2, ">f4"))


def test_the_result_is_float32_only_where_every_given_input_is():
    from lagbench.systems.backends import result_dtype

    assert result_dtype() == result_dtype(None) == "float64"
    for a in F32:
        assert result_dtype(a) == result_dtype(a, None) == "float32", a
        assert all(result_dtype(a, b) == "float32" for b in F32), a
        for b in F64_OR_OTHER:
            assert result_dtype(b) == result_dtype(a, b) == result_dtype(b, None, a) == "float64", (a, b)


def test_jax_backend_works_under_jit_and_vmap():
    import jax

    s = systems.get("double_pendulum")
    st = s.sample_states(16, 0)
    f = jax.jit(jax.vmap(lambda q, v, g: s.acceleration(q, v, backend="jax", g=g)))
    g = np.full(16, 9.8)
    np.testing.assert_allclose(np.asarray(f(st["q"], st["qdot"], g)), s.acceleration(st["q"], st["qdot"]),
                               rtol=1e-12, atol=1e-12)
