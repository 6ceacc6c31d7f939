"""Angles fed as cos and sin (`ModelSpec.periodic`): the spec validates the field and keeps the dicts of specs
without it; the hand-written derivatives (the fast LNN's terms, the PyTorch HNN's gradient, DeLaN's forward
tangents) carry the features' chain rule exactly, against autodiff through the model's own L, H or M in both
frameworks; and every kind is exactly 2 pi periodic in those coordinates (to rounding). JAX-vs-PyTorch parity
on identical weights: the periodic rows of test_models_parity.py; stacked members: test_models_stacked_torch.py."""
import jax
import jax.numpy as jnp
import numpy as np
import pytest
import torch

import lagbench.models.jax
import lagbench.models.torch
from lagbench.models import ModelSpec, init_params
from lagbench.models.jax.lnn import euler_lagrange as jax_euler_lagrange
from lagbench.models.jax.lnn import fast_terms as jax_fast_terms
from lagbench.models.torch.lnn import euler_lagrange as torch_euler_lagrange
from lagbench.models.torch.lnn import fast_terms as torch_fast_terms

FW = {"jax": (lagbench.models.jax, jnp.asarray, np.asarray), "torch": (lagbench.models.torch, torch.tensor, lambda t: t.detach().numpy())}
# [cos q0, sin q0, q1, cos q2, sin q2, qdot (3), gamma (3), extra]: every slot its own scale
SCALE = (0.5, 2.0, 1.5, 0.7, 1.3, 0.3, 1.1, 0.9, 0.02, 0.05, 0.01, 0.1)


def _case(kind, seed=0, **kw):
    spec = ModelSpec(kind=kind, dof=3, hidden=(16, 16), dtype="float64", periodic=(0, 2), **kw)
    rng = np.random.default_rng(seed)
    q = rng.uniform(-20, 20, (7, 3))     # unwrapped angles, several turns
    v = 0.9 * np.tanh(rng.normal(size=(7, 3)))
    e = rng.normal(size=(7, kw.get("extra_inputs", 0) or 3))
    return spec, init_params(spec, seed=seed), q, v, e


def test_spec_checks_the_field_and_keeps_default_dicts():
    plain = ModelSpec(kind="lnn", dof=2)
    assert "periodic" not in plain.to_dict()    # existing specs keep their dicts, hence their training keys
    spec = ModelSpec(kind="delan", dof=2, periodic=[1])
    assert spec.periodic == (1,) and spec.mlp_sizes()[0] == 3 and spec.to_dict()["periodic"] == [1]
    assert ModelSpec.from_dict(spec.to_dict()) == spec and hash(ModelSpec.from_dict(spec.to_dict())) == hash(spec)
    assert ModelSpec(kind="lnn", dof=2, periodic=(0, 1), lorentz_factor=True, extra_inputs=1).mlp_sizes()[0] == 9
    assert ModelSpec(kind="baseline", dof=2, periodic=(0,), extra_inputs=2).mlp_sizes()[0] == 7


@pytest.mark.parametrize("bad, match", [
    ({"periodic": (2,)}, r"ints in \[0, 2\)"),
    ({"periodic": (-1,)}, r"ints in \[0, 2\)"),
    ({"periodic": (0.0,)}, r"ints in \[0, 2\)"),
    ({"periodic": (True,)}, r"ints in \[0, 2\)"),
    ({"periodic": 0}, r"ints in \[0, 2\)"),
    ({"periodic": (1, 0)}, "unique and sorted"),
    ({"periodic": (0, 0)}, "unique and sorted"),
    ({"periodic": (0,), "angle_wrap": True}, "periodic and angle_wrap exclude each other"),
    ({"periodic": (0,), "kind": "lgn"}, "periodic is for kinds baseline, lnn, hnn, delan, not 'lgn'"),
    ({"periodic": (0,), "input_scale": (1.0,) * 4}, "input_scale needs 5 entries"),
])
def test_spec_refuses_bad_periodic(bad, match):
    with pytest.raises(ValueError, match=match):
        ModelSpec(**({"kind": "lnn", "dof": 2, "hidden": (8,)} | bad))


@pytest.mark.parametrize("kw", [{}, {"extra_inputs": 1, "lorentz_factor": True, "input_scale": SCALE}])
def test_hand_written_lnn_terms_equal_autodiff(kw):
    spec, p, q, v, e = _case("lnn", seed=1, **kw)
    e = e if spec.extra_inputs else None
    for fw, fast_terms in (("jax", jax_fast_terms), ("torch", torch_fast_terms)):
        mod, arr, back = FW[fw]
        m = mod.build(spec, p)
        args = [None if a is None else arr(a) for a in (q, v, e)]
        h, r = (back(t) for t in m._fast_terms(*args))
        ha, ra = (back(t) for t in fast_terms(m._lagrangian, *args))
        assert np.abs(h - ha).max() <= 1e-12 * np.abs(ha).max(), fw
        assert np.abs(r - ra).max() <= 1e-12 * np.abs(ra).max(), fw


@pytest.mark.parametrize("fw", ["jax", "torch"])
def test_fast_lnn_equals_the_paper_formulation(fw):
    mod, arr, back = FW[fw]
    spec, p, q, v, _ = _case("lnn", seed=2)
    fast = back(mod.build(spec, p).acceleration(arr(q), arr(v)))
    paper = back(mod.build(ModelSpec.from_dict(spec.to_dict() | {"formulation": "paper"}), p).acceleration(arr(q), arr(v)))
    el = torch_euler_lagrange if fw == "torch" else jax_euler_lagrange
    generic = back(el(mod.build(spec, p)._lagrangian, arr(q), arr(v), "paper"))
    assert np.abs(fast - paper).max() <= 1e-9 * np.abs(paper).max()
    assert np.abs(fast - generic).max() <= 1e-9 * np.abs(paper).max()


def test_torch_hnn_hand_written_gradient_equals_autograd():
    spec, p, q, v, e = _case("hnn", seed=3, extra_inputs=1, lorentz_factor=True, input_scale=SCALE)
    m = lagbench.models.torch.build(spec, p)
    x, y = torch.tensor(q, requires_grad=True), torch.tensor(v, requires_grad=True)
    dh_dx, dh_dy = torch.autograd.grad(m.hamiltonian(x, y, torch.tensor(e)).sum(), (x, y))
    xdot, ydot = m.time_derivative(torch.tensor(q), torch.tensor(v), torch.tensor(e))
    assert torch.allclose(xdot, dh_dy, rtol=0, atol=1e-12) and torch.allclose(ydot, -dh_dx, rtol=0, atol=1e-12)


def _prediction(m, kind, q, v, e):
    if kind == "hnn":
        return np.concatenate([np.asarray(t.detach() if hasattr(t, "detach") else t) for t in m.time_derivative(q, v)], -1)
    out = m.inverse_dynamics(q, v, e) if kind == "delan" else m.acceleration(q, v)
    return np.asarray(out.detach() if hasattr(out, "detach") else out)


@pytest.mark.parametrize("fw", ["jax", "torch"])
@pytest.mark.parametrize("kind, kw", [("lnn", {}), ("lnn", {"formulation": "paper"}), ("hnn", {}),
                                      ("delan", {"init": "xavier"}), ("baseline", {})])
def test_periodic_coordinates_are_exactly_2pi_periodic(fw, kind, kw):
    mod, arr, _ = FW[fw]
    spec, p, q, v, e = _case(kind, seed=4, **kw)
    m = mod.build(spec, p)
    base = _prediction(m, kind, arr(q), arr(v), arr(e))
    for k, periodic in ((0, True), (1, False), (2, True)):
        shift = np.zeros(3)
        shift[k] = 2 * np.pi * (3 if k else -2)
        moved = _prediction(m, kind, arr(q + shift), arr(v), arr(e))
        err = np.abs(moved - base).max() / np.abs(base).max()
        assert (err <= 1e-11) if periodic else (err > 1e-3), (k, err)


@pytest.mark.parametrize("fw", ["jax", "torch"])
def test_delan_hand_written_tangents_equal_autodiff(fw):
    """dLc/dq and dV/dq of the forward tangents against autodiff of the heads, hence dM/dq; the whole model
    against the Euler-Lagrange equation of its own L."""
    mod, arr, back = FW[fw]
    spec, p, q, v, _ = _case("delan", seed=5, init="xavier", input_scale=(0.5, 2.0, 1.5, 0.7, 1.3))
    m = mod.build(spec, p)
    lc, dlc, _, dv = (back(t) for t in m._heads_tangents(arr(q)))
    if fw == "jax":
        jac_lc = np.asarray(jax.vmap(jax.jacfwd(lambda a: m._heads(a)[0]))(jnp.asarray(q)))      # (B, i, j, k)
        jac_v = np.asarray(jax.vmap(jax.grad(lambda a: m._heads(a)[1]))(jnp.asarray(q)))
        jac_m = np.asarray(jax.vmap(jax.jacfwd(m.mass_matrix))(jnp.asarray(q)))
    else:
        jac_lc = torch.func.vmap(torch.func.jacfwd(lambda a: m._heads(a)[0]))(torch.tensor(q)).detach().numpy()
        jac_v = torch.func.vmap(torch.func.grad(lambda a: m._heads(a)[1]))(torch.tensor(q)).detach().numpy()
        jac_m = torch.func.vmap(torch.func.jacfwd(m.mass_matrix))(torch.tensor(q)).detach().numpy()
    np.testing.assert_allclose(dlc, np.moveaxis(jac_lc, -1, 1), rtol=0, atol=1e-12 * np.abs(jac_lc).max())
    np.testing.assert_allclose(dv, jac_v, rtol=0, atol=1e-12 * np.abs(jac_v).max())
    dm = dlc @ np.swapaxes(lc, -1, -2)[:, None] + lc[:, None] @ np.swapaxes(dlc, -1, -2)   # dM/dq_k
    np.testing.assert_allclose(dm, np.moveaxis(jac_m, -1, 1), rtol=0, atol=1e-11 * np.abs(jac_m).max())
    h = 1e-6   # and a central difference of M along q_0 (a periodic coordinate)
    mp, mm = (back(m.mass_matrix(arr(q + s * np.array([h, 0.0, 0.0])))) for s in (1, -1))
    np.testing.assert_allclose(dm[:, 0], (mp - mm) / (2 * h), rtol=0, atol=1e-7 * np.abs(dm).max())
    el = torch_euler_lagrange if fw == "torch" else jax_euler_lagrange
    free, want = back(m.acceleration(arr(q), arr(v))), back(el(m.lagrangian, arr(q), arr(v), "paper"))
    assert np.abs(free - want).max() <= 1e-9 * np.abs(want).max()
