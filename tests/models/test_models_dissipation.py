"""The Rayleigh dissipation of the HNN and DeLaN (`ModelSpec.dissipation`; the LNN's: test_models_lnn.py), in
both frameworks: the HNN's Hamiltonian falls at dH/dt = -sum b (dH/dy)^2 along its own flow, and DeLaN's
torque gains exactly b * qdot (its forward model loses b * qdot through M^-1)."""
import numpy as np
import pytest
import torch

import lagbench.models.jax
import lagbench.models.torch
from lagbench.models import ModelSpec, init_params

RAW = np.array([0.4, -0.7])
B = np.log1p(np.exp(RAW))


def _np(x):
    return x.detach().numpy() if hasattr(x, "detach") else np.asarray(x)


def _build(fw, spec, params):
    conv = torch.tensor if fw == "torch" else np.asarray
    return (lagbench.models.torch.build if fw == "torch" else lagbench.models.jax.build)(spec, {k: conv(v) for k, v in params.items()})


def _pair(kind, **kw):
    spec = ModelSpec(kind=kind, dof=2, hidden=(16, 16), dtype="float64", init="xavier", dissipation=True, **kw)
    params = {**init_params(spec, seed=1), "dissipation.raw": RAW}
    plain = ModelSpec(kind=kind, dof=2, hidden=(16, 16), dtype="float64", init="xavier", **kw)
    return spec, params, plain, {k: v for k, v in params.items() if k != "dissipation.raw"}


@pytest.mark.parametrize("fw", ["jax", "torch"])
def test_the_hnn_loses_its_hamiltonian_at_the_rayleigh_rate(fw):
    spec, params, plain, p0 = _pair("hnn", activation="tanh")
    m, m0 = _build(fw, spec, params), _build(fw, plain, p0)
    conv = torch.tensor if fw == "torch" else np.asarray
    x, y = np.random.default_rng(0).normal(size=(2, 6, 2))
    xdot, ydot = (_np(v) for v in m.time_derivative(conv(x), conv(y)))
    xdot0, ydot0 = (_np(v) for v in m0.time_derivative(conv(x), conv(y)))
    np.testing.assert_allclose(xdot, xdot0, rtol=1e-12)
    np.testing.assert_allclose(ydot, ydot0 - B * xdot, rtol=1e-10, atol=1e-12)
    # dH/dt = dH/dx . xdot + dH/dy . ydot, with dH/dx = -ydot0 and dH/dy = xdot
    np.testing.assert_allclose(np.sum(-ydot0 * xdot + xdot * ydot, -1), -np.sum(B * xdot ** 2, -1), rtol=1e-10)


@pytest.mark.parametrize("fw", ["jax", "torch"])
def test_delans_torque_gains_the_friction_and_its_forward_model_loses_it(fw):
    spec, params, plain, p0 = _pair("delan")
    m, m0 = _build(fw, spec, params), _build(fw, plain, p0)
    conv = torch.tensor if fw == "torch" else np.asarray
    q, qd, qdd = np.random.default_rng(1).normal(size=(3, 6, 2))
    tau = _np(m.inverse_dynamics(conv(q), conv(qd), conv(qdd)))
    np.testing.assert_allclose(tau, _np(m0.inverse_dynamics(conv(q), conv(qd), conv(qdd))) + B * qd, rtol=1e-10)
    back = _np(m.acceleration(conv(q), conv(qd), conv(tau)))   # the forward model inverts the inverse one
    np.testing.assert_allclose(back, qdd, rtol=1e-8, atol=1e-10)
