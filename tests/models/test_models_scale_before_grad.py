"""The original LNN code's input-scaling convention (`Lnn.scale_q_before_grad`): L's q-derivatives are
taken in the scaled q, x = s_q q, so the Euler-Lagrange equation is H qddot = dL/dx - (d2L/dqdot dx) qdot with
the true qdot. With s_q the same on every slot qddot is the differentiated-through one divided by s_q (1-D: the
original's relativistic notebook, s = 1/10); with slots scaled apart, and with periodic features, the models'
fast and paper formulations in both frameworks equal an autodiff reference written here; H and L's value do
not change. The spec refuses the field off the LNN or without an input_scale and keeps older dicts.
JAX-vs-PyTorch parity on identical weights (and loss gradients): the scale_q_before_grad rows of
test_models_parity.py."""
import dataclasses

import jax
import jax.numpy as jnp
import numpy as np
import pytest
import torch

import lagbench.models.jax
import lagbench.models.torch
from lagbench.models import ModelSpec, init_params
from lagbench.models.jax.mlp import mlp

FW = {"jax": (lagbench.models.jax, jnp.asarray, np.asarray), "torch": (lagbench.models.torch, torch.tensor, lambda t: t.detach().numpy())}


def _states(dof, extra, seed, n=9):
    rng = np.random.default_rng(seed)
    q = rng.uniform(-10, 10, (n, dof))
    v = 0.99 * np.tanh(2 * rng.normal(size=(n, dof)))
    return q, v, 10 * rng.normal(size=(n, extra))


def _acc(spec, params, fw, q, v, e):
    pkg, arr, back = FW[fw]
    return back(pkg.build(spec, params).acceleration(arr(q), arr(v), arr(e)))


@pytest.mark.parametrize("fw", ["jax", "torch"])
@pytest.mark.parametrize("formulation", ["fast", "paper"])
@pytest.mark.parametrize("dof, s", [(1, 0.1), (3, 0.25)])
def test_uniform_q_scale_divides_qddot_by_it(fw, formulation, dof, s):
    """1-D as the relativistic notebook (q, g / 10; qdot raw), and 3-D with one q scale: qddot / s_q."""
    scale = (s,) * dof + (1.0,) * dof + (0.1,)
    plain = ModelSpec(kind="lnn", dof=dof, hidden=(16, 16), dtype="float64", extra_inputs=1, input_scale=scale,
                      formulation=formulation)
    orig = dataclasses.replace(plain, scale_q_before_grad=True)
    params = init_params(plain, seed=dof)
    q, v, e = _states(dof, 1, seed=dof)
    want = _acc(plain, params, fw, q, v, e) / s
    got = _acc(orig, params, fw, q, v, e)
    assert np.abs(got - want).max() <= 1e-10 * np.abs(want).max()


def _reference(spec, params, q, v, e, offset=None):
    """qddot of the convention by jax.grad / jax.hessian of the network in its q slots directly. Without
    periodic features the network is taken as a function of x = s_q q; with them, of q through
    x_q = f(q) + c, c = (s_q - 1) f(q0) held fixed at the state (value s_q f(q0), derivative df/dq)."""
    nq, d = spec.q_width(), spec.dof
    s = np.asarray(spec.input_scale)
    s_q, s_rest = s[:nq], s[nq:]

    def net(xq, v1, e1):
        rest = jnp.concatenate([v1, 1.0 / jnp.sqrt(1.0 - v1 ** 2), e1]) if spec.lorentz_factor else jnp.concatenate([v1, e1])
        return mlp(params, jnp.concatenate([xq, rest * s_rest]), spec)[0]

    def one(q1, v1, e1):
        if offset is None:
            L, at = net, s_q * q1
        else:
            c = (s_q - 1.0) * offset(q1)
            L, at = (lambda a, b, e2: net(offset(a) + c, b, e2)), q1
        g = jax.grad(L, 0)(at, v1, e1)
        hess = jax.hessian(L, 1)(at, v1, e1)
        mixed = jax.jacobian(jax.grad(L, 1), 0)(at, v1, e1)   # (d, d): d2L / dqdot_j dx_i
        return jnp.linalg.solve(hess, g - mixed @ v1)
    assert nq == d or offset is not None
    return np.asarray(jax.vmap(one)(*(jnp.asarray(a) for a in (q, v, e))))


def _features(q1):
    """cos, sin of q0 and q2, q1 linear: the q part of periodic=(0, 2) for one state."""
    return jnp.stack([jnp.cos(q1[0]), jnp.sin(q1[0]), q1[1], jnp.cos(q1[2]), jnp.sin(q1[2])])


CASES = {
    # [q (3), qdot (3), gamma (3), g]: every slot its own scale, the Lorentz factor on the velocity side
    "linear": (dict(lorentz_factor=True, input_scale=(0.1, 0.5, 2.0, 1.0, 0.7, 1.3, 0.01, 0.02, 0.05, 0.1)), None),
    # [cos q0, sin q0, q1, cos q2, sin q2, qdot (3), g]
    "periodic": (dict(periodic=(0, 2), input_scale=(0.5, 2.0, 0.1, 0.7, 1.3, 1.0, 0.7, 1.3, 0.1)), _features),
}


@pytest.mark.parametrize("fw", ["jax", "torch"])
@pytest.mark.parametrize("formulation", ["fast", "paper"])
@pytest.mark.parametrize("case", list(CASES))
def test_multi_d_qddot_equals_the_autodiff_reference(fw, formulation, case):
    kw, offset = CASES[case]
    spec = ModelSpec(kind="lnn", dof=3, hidden=(16, 16), dtype="float64", extra_inputs=1, formulation=formulation,
                     scale_q_before_grad=True, **kw)
    params = init_params(spec, seed=11)
    q, v, e = _states(3, 1, seed=12)
    want = _reference(spec, params, q, v, e, offset)
    got = _acc(spec, params, fw, q, v, e)
    assert np.abs(got - want).max() <= 1e-9 * np.abs(want).max()
    plain = dataclasses.replace(spec, scale_q_before_grad=False)
    assert np.abs(_acc(plain, params, fw, q, v, e) - want).max() > 1e-3 * np.abs(want).max()   # the flag matters


@pytest.mark.parametrize("fw", ["jax", "torch"])
def test_lagrangian_value_and_velocity_hessian_are_unchanged(fw):
    pkg, arr, back = FW[fw]
    kw, _ = CASES["periodic"]
    spec = ModelSpec(kind="lnn", dof=3, hidden=(16, 16), dtype="float64", extra_inputs=1, scale_q_before_grad=True, **kw)
    params = init_params(spec, seed=4)
    a, b = pkg.build(spec, params), pkg.build(dataclasses.replace(spec, scale_q_before_grad=False), params)
    x = [arr(t) for t in _states(3, 1, seed=5)]
    for name in ("lagrangian", "velocity_hessian"):
        want = back(getattr(b, name)(*x))
        assert np.abs(back(getattr(a, name)(*x)) - want).max() <= 1e-14 * np.abs(want).max(), name


def test_spec_refuses_the_field_off_the_lnn_and_keeps_old_dicts():
    plain = ModelSpec(kind="lnn", dof=1, extra_inputs=1, input_scale=(0.1, 1.0, 0.1))
    assert "scale_q_before_grad" not in plain.to_dict()   # existing specs keep their dicts, hence their keys
    orig = dataclasses.replace(plain, scale_q_before_grad=True)
    assert orig.to_dict()["scale_q_before_grad"] is True and ModelSpec.from_dict(orig.to_dict()) == orig
    assert orig.to_dict() != plain.to_dict()
    with pytest.raises(ValueError, match="scale_q_before_grad is for kind lnn, not 'hnn'"):
        ModelSpec(kind="hnn", dof=1, extra_inputs=1, input_scale=(0.1, 1.0, 0.1), scale_q_before_grad=True)
    with pytest.raises(ValueError, match="with an input_scale"):
        ModelSpec(kind="lnn", dof=1, scale_q_before_grad=True)
    with pytest.raises(ValueError, match="must be True or False"):
        ModelSpec(kind="lnn", dof=1, input_scale=(0.1, 1.0), scale_q_before_grad=1)
