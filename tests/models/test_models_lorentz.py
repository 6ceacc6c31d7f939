"""The Lorentz-factor input (`ModelSpec.lorentz_factor`): the hand-written LNN terms and the PyTorch HNN's
hand-written gradient carry gamma's chain rule exactly (against autodiff through the model's own L or H),
the frameworks agree on identical weights, gamma's slopes are its derivatives, and a spec without the
feature keeps its old dict (so its training keys do not change)."""
import jax
import jax.numpy as jnp
import numpy as np
import pytest
import torch

import lagbench.models.jax
import lagbench.models.torch
from lagbench.models import ModelSpec, init_params
from lagbench.models.jax.lnn import fast_terms as jax_fast_terms
from lagbench.models.lorentz import lorentz_factor, lorentz_slopes
from lagbench.models.torch.lnn import fast_terms as torch_fast_terms

SCALE = (0.5, 2.0, 1.0, 1.0, 0.01, 0.02, 0.1)   # [q (2), qdot (2), gamma (2), g]: every slot its own scale


def _case(kind, seed=3):
    spec = ModelSpec(kind=kind, dof=2, hidden=(16, 16), dtype="float64", extra_inputs=1, lorentz_factor=True,
                     input_scale=SCALE)
    rng = np.random.default_rng(seed)
    q, e = rng.normal(size=(6, 2)), rng.normal(size=(6, 1))
    v = 0.999 * np.tanh(2 * rng.normal(size=(6, 2)))   # up to gamma ~ 22: the feature's curvature matters
    return spec, init_params(spec, seed=seed), q, v, e


def test_hand_written_lnn_terms_equal_autodiff_through_gamma():
    spec, p, q, v, e = _case("lnn")
    mj, mt = lagbench.models.jax.build(spec, p), lagbench.models.torch.build(spec, p)
    hj, rj = mj._fast_terms(jnp.asarray(q), jnp.asarray(v), jnp.asarray(e))
    ha, ra = jax_fast_terms(mj._lagrangian, jnp.asarray(q), jnp.asarray(v), jnp.asarray(e))
    ht, rt = mt._fast_terms(torch.tensor(q), torch.tensor(v), torch.tensor(e))
    hb, rb = torch_fast_terms(mt._lagrangian, torch.tensor(q), torch.tensor(v), torch.tensor(e))
    scale = float(np.abs(np.asarray(ha)).max())
    assert np.abs(np.asarray(hj - ha)).max() <= 1e-12 * scale and np.abs(np.asarray(rj - ra)).max() <= 1e-12
    assert (ht - hb).abs().max().item() <= 1e-12 * scale and (rt - rb).abs().max().item() <= 1e-12


@pytest.mark.parametrize("kind", ["lnn", "hnn"])
def test_frameworks_agree_with_gamma(kind):
    spec, p, q, v, e = _case(kind, seed=5)
    mj, mt = lagbench.models.jax.build(spec, p), lagbench.models.torch.build(spec, p)
    J, T = (jnp.asarray(a) for a in (q, v, e)), (torch.tensor(a) for a in (q, v, e))
    if kind == "lnn":
        a, b = np.asarray(mj.acceleration(*J)), mt.acceleration(*T).detach().numpy()
        assert np.abs(a - b).max() <= 1e-10 * np.abs(a).max()
        return
    aj, at = mj.time_derivative(*J), mt.time_derivative(*T)
    for x, y in zip(aj, at, strict=True):
        assert np.abs(np.asarray(x) - y.detach().numpy()).max() <= 1e-12


def test_torch_hnn_hand_written_gradient_includes_gamma():
    spec, p, q, v, e = _case("hnn", seed=7)
    mt = lagbench.models.torch.build(spec, p)
    y = torch.tensor(v, requires_grad=True)
    x = torch.tensor(q, requires_grad=True)
    (dh_dx, dh_dy) = torch.autograd.grad(mt.hamiltonian(x, y, torch.tensor(e)).sum(), (x, y))
    xdot, ydot = mt.time_derivative(torch.tensor(q), torch.tensor(v), torch.tensor(e))
    assert torch.allclose(xdot, dh_dy, rtol=0, atol=1e-12) and torch.allclose(ydot, -dh_dx, rtol=0, atol=1e-12)


def test_lorentz_slopes_are_gammas_derivatives():
    v = jnp.linspace(-0.999, 0.999, 41, dtype=jnp.float64)
    d1 = jax.vmap(jax.grad(lorentz_factor))(v)
    d2 = jax.vmap(jax.grad(jax.grad(lorentz_factor)))(v)
    s1, s2 = lorentz_slopes(v)
    assert np.allclose(s1, d1, rtol=1e-12, atol=0) and np.allclose(s2, d2, rtol=1e-12, atol=0)
    assert float(lorentz_factor(jnp.asarray(0.6))) == pytest.approx(1.25)


def test_spec_gamma_widens_the_input_and_leaves_old_specs_alone():
    plain = ModelSpec(kind="lnn", dof=2, extra_inputs=1)
    assert "lorentz_factor" not in plain.to_dict()    # older specs keep their dicts, hence their training keys
    lz = ModelSpec(kind="hnn", dof=2, extra_inputs=1, lorentz_factor=True)
    assert lz.mlp_sizes()[0] == 7 and ModelSpec.from_dict(lz.to_dict()) == lz
    with pytest.raises(ValueError, match="lorentz_factor is for kinds"):
        ModelSpec(kind="baseline", dof=2, lorentz_factor=True)
    with pytest.raises(ValueError, match="input_scale needs 7"):
        ModelSpec(kind="lnn", dof=2, extra_inputs=1, lorentz_factor=True, input_scale=(1.0,) * 5)
