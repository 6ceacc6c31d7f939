"""DeLaN: the mass matrix is symmetric positive definite for random parameters and inputs; the
inverse and forward models invert each other and agree with the Euler-Lagrange equation of L."""
import numpy as np
import pytest
import torch
from hypothesis import given, settings
from hypothesis import strategies as st
from models_testkit import assert_rel, spec_params

import lagbench.models.torch
from lagbench.models.torch.lnn import euler_lagrange


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2 ** 31 - 1), dof=st.integers(1, 4), scale=st.floats(0.1, 30.0),
       init=st.sampled_from(["xavier", "kaiming", "pytorch_default", "cranmer2020"]))
def test_mass_matrix_is_symmetric_positive_definite(seed, dof, scale, init):
    spec, params = spec_params(seed=seed, kind="delan", dof=dof, dtype="float64", init=init, hidden=(16, 16))
    q = torch.tensor(np.random.default_rng(seed).normal(scale=scale, size=(32, dof)))
    m = lagbench.models.torch.build(spec, params).mass_matrix(q).detach().numpy()
    np.testing.assert_array_equal(m, np.swapaxes(m, -1, -2))
    # eigvalsh is backward stable: its error is a few eps times the matrix norm, which grows with the
    # entries (up to ~1e5 here), so the bound eps_delan holds up to that rounding
    rounding = 10 * dof * np.finfo(np.float64).eps * np.linalg.norm(m, ord=2, axis=(-2, -1))
    assert np.all(np.linalg.eigvalsh(m) >= spec.own.eps - rounding[:, None])


def test_forward_and_inverse_models_are_consistent_with_euler_lagrange():
    spec, params = spec_params(kind="delan", dof=3, dtype="float64", init="xavier")
    model = lagbench.models.torch.build(spec, params)
    rng = np.random.default_rng(0)
    q, qdot, tau = (torch.tensor(rng.normal(size=(10, 3))) for _ in range(3))
    qddot = model.acceleration(q, qdot, tau)
    assert_rel(model.inverse_dynamics(q, qdot, qddot).detach(), tau, "float64", "tau round trip", factor=100)
    free = model.acceleration(q, qdot)
    assert_rel(free.detach(), euler_lagrange(model.lagrangian, q, qdot, "paper").detach(), "float64",
               "DeLaN terms vs Euler-Lagrange of its L", factor=100)
    c = model.coriolis(q, torch.zeros_like(qdot))
    assert torch.all(c == 0)


@pytest.mark.parametrize("d", [1, 2, 5, 8])
def test_unrolled_spd_solve_matches_linalg_solve(d):
    """`spd_solve_unrolled` (what the exported DeLaN acceleration uses) against torch.linalg.solve on
    random SPD matrices with a leading batch shape."""
    from lagbench.models.torch.delan import spd_solve_unrolled

    rng = np.random.default_rng(d)
    a = torch.tensor(rng.normal(size=(2, 3, d, d)))
    m = a @ a.transpose(-1, -2) + 0.1 * torch.eye(d, dtype=torch.float64)
    b = torch.tensor(rng.normal(size=(2, 3, d)))
    want = torch.linalg.solve(m, b[..., None])[..., 0]
    np.testing.assert_allclose(spd_solve_unrolled(m, b).numpy(), want.numpy(), rtol=1e-9, atol=1e-9)
