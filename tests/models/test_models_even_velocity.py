"""A Lagrangian even in qdot (`Lnn.even_velocity`): L = (N(q, qdot) + N(q, -qdot)) / 2. Its accelerations
without dissipation are even in qdot (no force odd in qdot is left to the conservative part) and with a
dissipation their odd part is exactly the friction's -H^-1 b qdot; the fast formulation's averaged terms equal
an autodiff reference of the symmetrised network in both frameworks, and the flag changes a model that is not
already even. JAX-vs-PyTorch parity on identical weights: the even_velocity rows of test_models_parity.py;
stacked members: test_models_stacked_torch.py."""
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

FW = {"jax": (lagbench.models.jax, jnp.asarray, np.asarray),
      "torch": (lagbench.models.torch, torch.tensor, lambda t: t.detach().numpy())}


def _states(dof, seed, n=11):
    rng = np.random.default_rng(seed)
    return rng.uniform(-3, 3, (n, dof)), rng.normal(size=(n, dof)) * 2


def _spec(**kw):
    return ModelSpec(**({"kind": "lnn", "dof": 2, "hidden": (16, 16), "dtype": "float64", "periodic": (0,),
                         "input_scale": (0.5, 2.0, 0.7, 0.3, 1.1), "even_velocity": True} | kw))


def _reference(spec, params, q, v):
    """qddot of (N(q, v) + N(q, -v)) / 2 by jax.grad / jax.hessian, N the MLP on [cos q0, sin q0, q1, v]."""
    s = jnp.asarray(spec.input_scale)

    def net(q1, v1):
        return mlp(params, s * jnp.concatenate([jnp.stack([jnp.cos(q1[0]), jnp.sin(q1[0]), q1[1]]), v1]), spec)[0]

    def L(q1, v1):
        return (net(q1, v1) + net(q1, -v1)) / 2

    def one(q1, v1):
        mixed = jax.jacobian(jax.grad(L, 1), 0)(q1, v1)
        return jnp.linalg.solve(jax.hessian(L, 1)(q1, v1), jax.grad(L, 0)(q1, v1) - mixed @ v1)
    return np.asarray(jax.vmap(one)(jnp.asarray(q), jnp.asarray(v)))


@pytest.mark.parametrize("fw", ["jax", "torch"])
@pytest.mark.parametrize("formulation", ["fast", "paper"])
def test_qddot_equals_the_autodiff_reference_of_the_symmetrised_network(fw, formulation):
    pkg, arr, back = FW[fw]
    spec = _spec(formulation=formulation)
    params = init_params(spec, seed=3)
    q, v = _states(2, seed=4)
    want = _reference(spec, params, q, v)
    got = back(pkg.build(spec, params).acceleration(arr(q), arr(v)))
    assert np.abs(got - want).max() <= 1e-9 * np.abs(want).max()
    plain = back(pkg.build(dataclasses.replace(spec, even_velocity=False), params).acceleration(arr(q), arr(v)))
    assert np.abs(plain - want).max() > 1e-3 * np.abs(want).max()   # the flag matters


@pytest.mark.parametrize("fw", ["jax", "torch"])
def test_accelerations_are_even_in_qdot_and_the_friction_is_their_only_odd_part(fw):
    pkg, arr, back = FW[fw]
    spec = _spec(dissipation=True)
    params = dict(init_params(spec, seed=5))
    params["dissipation.raw"] = np.asarray([0.3, -1.0])
    q, v = _states(2, seed=6)
    conservative = pkg.build(dataclasses.replace(spec, dissipation=False),
                             {k: x for k, x in params.items() if k != "dissipation.raw"})
    a, b = (back(conservative.acceleration(arr(q), arr(s * v))) for s in (1, -1))
    assert np.abs(a - b).max() <= 1e-10 * np.abs(a).max()
    model = pkg.build(spec, params)
    odd = (back(model.acceleration(arr(q), arr(v))) - back(model.acceleration(arr(q), arr(-v)))) / 2
    hess = back(model.velocity_hessian(arr(q), arr(v)))
    side = np.sign(np.trace(hess, axis1=1, axis2=2))[:, None]
    friction = -np.linalg.solve(hess, (side * np.log1p(np.exp(params["dissipation.raw"])) * v)[..., None])[..., 0]
    assert np.abs(odd - friction).max() <= 1e-10 * np.abs(friction).max()
    plain = pkg.build(dataclasses.replace(spec, even_velocity=False), params)   # a plain MLP has odd forces of its own
    odd_plain = (back(plain.acceleration(arr(q), arr(v))) - back(plain.acceleration(arr(q), arr(-v)))) / 2
    assert np.abs(odd_plain - friction).max() > 1e-3 * np.abs(friction).max()


@pytest.mark.parametrize("fw", ["jax", "torch"])
def test_lagrangian_is_the_average_over_plus_and_minus_qdot(fw):
    pkg, arr, back = FW[fw]
    spec = _spec()
    params = init_params(spec, seed=7)
    q, v = _states(2, seed=8)
    plain = pkg.build(dataclasses.replace(spec, even_velocity=False), params)
    want = (back(plain.lagrangian(arr(q), arr(v))) + back(plain.lagrangian(arr(q), arr(-v)))) / 2
    assert np.abs(back(pkg.build(spec, params).lagrangian(arr(q), arr(v))) - want).max() <= 1e-14 * np.abs(want).max()


def test_spec_keeps_old_dicts_and_refuses_the_field_off_the_lnn():
    plain = ModelSpec(kind="lnn", dof=2)
    assert "even_velocity" not in plain.to_dict()   # existing specs keep their dicts, hence their keys
    even = dataclasses.replace(plain, even_velocity=True)
    assert even.to_dict()["even_velocity"] is True and ModelSpec.from_dict(even.to_dict()) == even
    with pytest.raises(ValueError, match="even_velocity is for kind lnn, not 'hnn'"):
        ModelSpec(kind="hnn", dof=2, even_velocity=True)
    with pytest.raises(ValueError, match="must be True or False"):
        ModelSpec(kind="lnn", dof=2, even_velocity=1)
