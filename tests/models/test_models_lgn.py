"""Lagrangian graph network: the banded O(n) path equals the dense path (cyclic wrap included), for
several grid sizes and radii, in both frameworks; a model built at n = 10 runs at n = 100."""
import numpy as np
import pytest
import torch
from models_testkit import assert_rel, make_inputs, spec_params, to_jax

import lagbench.models.jax
import lagbench.models.torch
from lagbench.models import ModelSpec


@pytest.mark.parametrize("n, r", [(5, 1), (7, 1), (10, 1), (13, 1), (9, 2), (12, 2), (100, 1)])
def test_banded_equals_dense_torch(n, r):
    spec, params = spec_params(kind="lgn", dof=10, dtype="float64", lgn_radius=r, formulation="banded")
    x = make_inputs(spec, batch=4, seed=n, n=n)
    q, qdot = torch.tensor(x["q"]), torch.tensor(x["qdot"])
    banded, n_bad = lagbench.models.torch.build(spec, params).acceleration_info(q, qdot)
    dense_spec = ModelSpec.from_dict(spec.to_dict() | {"formulation": "dense"})
    dense = lagbench.models.torch.build(dense_spec, params).acceleration(q, qdot)
    assert banded.shape == (4, n) and int(n_bad) == 0
    assert_rel(banded.detach(), dense.detach(), "float64", f"banded vs dense n={n} r={r}", factor=100)


def test_banded_equals_dense_jax_and_transfers_to_a_larger_grid():
    spec, params = spec_params(kind="lgn", dof=10, dtype="float64", formulation="banded")
    model = lagbench.models.jax.build(spec, params)
    dense = lagbench.models.jax.build(ModelSpec.from_dict(spec.to_dict() | {"formulation": "dense"}), params)
    for n in (10, 100):
        x = to_jax(make_inputs(spec, batch=3, seed=n, n=n))
        a, n_bad = model.acceleration_info(x["q"], x["qdot"])
        assert a.shape == (3, n) and int(n_bad) == 0
        assert_rel(a, dense.acceleration(x["q"], x["qdot"]), "float64", f"jax banded vs dense n={n}", factor=100)


def test_tiny_grids_use_the_dense_path():
    spec, params = spec_params(kind="lgn", dof=3, dtype="float64", formulation="banded")
    x = make_inputs(spec, batch=2, n=3)
    a = lagbench.models.torch.build(spec, params).acceleration(torch.tensor(x["q"]), torch.tensor(x["qdot"]))
    assert a.shape == (2, 3) and np.all(np.isfinite(a.detach().numpy()))


@pytest.mark.parametrize("fw", ["jax", "torch"])
@pytest.mark.parametrize("r", [1, 2])
def test_hand_written_band_terms_equal_generic_autodiff(r, fw):
    """Each framework's LGN: its per-node hand-written derivatives give the band and right-hand side that
    the generic coloured forward-over-reverse (`banded_terms` of its Lagrangian: jax.jvp of jax.grad,
    torch.func) gives, with input scaling and angle wrapping in the chain rule."""
    k = 2 * r + 1
    spec, params = spec_params(kind="lgn", dof=13, dtype="float64", lgn_radius=r, formulation="banded",
                               angle_wrap=True, input_scale=tuple(np.linspace(0.3, 2.0, 2 * k)))
    x = make_inputs(spec, batch=3, seed=r, n=13)
    if fw == "jax":
        import jax.numpy as jnp

        from lagbench.models.jax.lgn import banded_terms
        q, qdot, m = jnp.asarray(x["q"]) * 3.0, jnp.asarray(x["qdot"]), lagbench.models.jax.build(spec, params)
    else:
        from lagbench.models.torch.lgn import banded_terms
        q, qdot, m = torch.tensor(x["q"]) * 3.0, torch.tensor(x["qdot"]), lagbench.models.torch.build(spec, params)
    band, rhs = m._banded_terms(q, qdot)
    band_ref, rhs_ref = banded_terms(m._lagrangian, q, qdot, r)
    assert band.shape == (3, 13, 4 * r + 1)
    assert_rel(np.asarray(band.tolist()), np.asarray(band_ref.tolist()), "float64", "band")
    assert_rel(np.asarray(rhs.tolist()), np.asarray(rhs_ref.tolist()), "float64", "rhs")


def test_singular_band_takes_the_counted_pinv_fallback_with_finite_gradients():
    """An LGN blind to qdot (first-layer velocity weights zero) has a zero velocity Hessian: every sample's
    banded solve fails, takes pinv (q'' = pinv(0) rhs = 0) and is counted; training through it stays finite."""
    spec, params = spec_params(kind="lgn", dof=10, dtype="float64", formulation="banded")
    params["mlp.0.weight"][:, 3:] = 0.0
    x = make_inputs(spec, batch=4, seed=2, n=10)
    m = lagbench.models.torch.build(spec, params)
    a, n_bad = m.acceleration_info(torch.tensor(x["q"]), torch.tensor(x["qdot"]))
    assert int(n_bad) == 4
    np.testing.assert_allclose(a.detach().numpy(), 0.0, atol=1e-12)
    (a - 1.0).abs().sum().backward()
    assert all(torch.isfinite(p.grad).all() for p in m.parameters() if p.grad is not None)


def test_banded_euler_lagrange_info_is_one_public_mirror():
    """`banded_euler_lagrange_info(L_fn, q, qdot, r)` is in both frameworks' lgn.py with one contract:
    on the model's own Lagrangian it gives the LGN's banded accelerations and fallback count."""
    import jax.numpy as jnp

    from lagbench.models.jax.lgn import banded_euler_lagrange_info as jax_info
    from lagbench.models.torch.lgn import banded_euler_lagrange_info as torch_info

    spec, params = spec_params(kind="lgn", dof=10, dtype="float64", formulation="banded")
    x = make_inputs(spec, batch=3, seed=5, n=10)
    mt, mj = lagbench.models.torch.build(spec, params), lagbench.models.jax.build(spec, params)
    q, qdot = torch.tensor(x["q"]), torch.tensor(x["qdot"])
    a_t, n_t = torch_info(mt._lagrangian, q, qdot, spec.own.radius)
    a_j, n_j = jax_info(mj._lagrangian, jnp.asarray(x["q"]), jnp.asarray(x["qdot"]), spec.own.radius)
    assert a_t.shape == a_j.shape == (3, 10) and int(n_t) == int(n_j) == 0
    assert_rel(a_t.detach(), mt.acceleration(q, qdot).detach(), "float64", "torch L_fn vs model")
    assert_rel(a_t.detach(), np.asarray(a_j), "float64", "torch vs jax")
