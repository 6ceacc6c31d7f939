"""The PyTorch Euler-Lagrange solve: the closed-form small inverse against LAPACK, and the inference path
(no gradients: the inverse reused) against the training path (LU solve, I on the bad samples), with a
singular and a non-finite Hessian in the batch."""
import numpy as np
import pytest
import torch

from lagbench.models.torch.lnn import small_inverse, solve_with_fallback

RNG = np.random.default_rng(11)


@pytest.mark.parametrize("d", [1, 2, 3])
def test_small_inverse_is_the_inverse_and_flags_singular(d):
    h = torch.tensor(RNG.normal(size=(6, d, d)))
    h[2] = 0.0
    inv, info = small_inverse(h)
    good = [0, 1, 3, 4, 5]
    np.testing.assert_allclose(inv[good].numpy(), torch.linalg.inv(h[good]).numpy(), rtol=1e-10, atol=1e-12)
    assert info[2] != 0 and (info[good] == 0).all()


@pytest.mark.parametrize("d", [2, 4])
def test_inference_path_equals_the_training_path(d):
    hess = torch.tensor(RNG.normal(size=(5, d, d)))
    hess = hess @ hess.mT + torch.eye(d)
    hess[1] = 1.0                      # rank one: pinv
    hess[3, 0, 0] = float("nan")       # non-finite: NaN out, counted
    rhs = torch.tensor(RNG.normal(size=(5, d)))
    with torch.no_grad():
        x_inf, n_inf = solve_with_fallback(hess, rhs)
    x_train, n_train = solve_with_fallback(hess.clone().requires_grad_(True), rhs)
    assert int(n_inf) == int(n_train) == 2
    np.testing.assert_allclose(x_inf.numpy(), x_train.detach().numpy(), rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(x_inf[1].numpy(), (torch.linalg.pinv(hess[1]) @ rhs[1]).numpy(), rtol=1e-10)
    assert torch.isnan(x_inf[3]).all()
