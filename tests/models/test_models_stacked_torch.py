"""Stacked members (`models.torch.build_stacked`): K models of one spec as one module whose parameters carry
a leading K axis, run without torch.func.vmap (what `replication.training.train_torch.Members` trains). In
float64 each member's prediction, fallback count and loss gradient equal its own model's, for the kinds and
specs that `stacks`; the others are refused."""
import numpy as np
import pytest
import torch
from models_testkit import assert_rel, make_inputs

import lagbench.models.torch
from lagbench.models import ModelSpec, init_params
from lagbench.replication.training.objective import loss_value

K = 3
CASES = {
    "lnn_softplus_dp": dict(kind="lnn", dof=2, activation="softplus", angle_wrap=True, input_scale=(1.0, 1.0, 0.3, 0.3)),
    "lnn_tanh_extra": dict(kind="lnn", dof=2, activation="tanh", init="xavier", extra_inputs=2,
                           input_scale=(0.5, 2.0, 1.5, 0.3, 1.0, 1.0)),
    "lnn_lorentz": dict(kind="lnn", dof=2, activation="softplus", extra_inputs=1, lorentz_factor=True),
    "lnn_relu2_dof3": dict(kind="lnn", dof=3, activation="relu2"),
    "lnn_dissipation": dict(kind="lnn", dof=2, dissipation=True),
    "lnn_relu_falls_back": dict(kind="lnn", dof=2, activation="relu"),
    "baseline": dict(kind="baseline", dof=2, extra_inputs=1, angle_wrap=True),
    "lnn_periodic": dict(kind="lnn", dof=3, periodic=(0, 2), extra_inputs=1, lorentz_factor=True,
                         input_scale=(0.5, 2.0, 1.5, 0.7, 1.3, 0.3, 1.1, 0.9, 0.02, 0.05, 0.01, 0.1)),
    "baseline_periodic": dict(kind="baseline", dof=2, periodic=(1,)),
    "lnn_scale_before_grad": dict(kind="lnn", dof=2, extra_inputs=1, scale_q_before_grad=True,
                                  input_scale=(0.1, 0.5, 1.0, 1.0, 0.1)),
    "lnn_even_velocity": dict(kind="lnn", dof=2, periodic=(0, 1), dissipation=True, even_velocity=True),
}


def _members(fields):
    spec = ModelSpec(hidden=(24, 24), dtype="float64", **fields)
    params = [init_params(spec, seed=s) for s in range(K)]
    inputs = [make_inputs(spec, batch=12, seed=10 + s) for s in range(K)]
    if spec.lorentz_factor:   # velocities inside the light cone
        for x in inputs:
            x["qdot"] = 0.9 * x["qdot"]
    return spec, params, inputs


def _loss(model, x, axis=None):
    pred, n_bad = model.acceleration_info(x["q"], x["qdot"], x["extra"])
    return pred, n_bad, loss_value(pred, x["target"], None, "l1", axis)


@pytest.mark.parametrize("case", sorted(CASES))
def test_each_stacked_member_equals_its_own_model(case):
    spec, params, inputs = _members(CASES[case])
    stacked = lagbench.models.torch.build_stacked(spec, params)
    x = {k: None if inputs[0][k] is None else torch.tensor(np.stack([i[k] for i in inputs])) for k in inputs[0]}
    pred, n_bad, losses = _loss(stacked, x, axis=-1)
    assert losses.shape == (K,)
    losses.sum().backward()
    grads = {k: p.grad for k, p in stacked.named_parameters()}
    total_bad = 0
    for i in range(K):
        alone = lagbench.models.torch.build(spec, params[i])
        xi = {k: None if v is None else torch.tensor(v) for k, v in inputs[i].items()}
        p_i, bad_i, loss_i = _loss(alone, xi)
        loss_i.backward()
        total_bad += int(bad_i)
        assert_rel(pred[i].detach().numpy(), p_i.detach().numpy(), "float64", f"{case} member {i} prediction")
        assert_rel(losses[i].detach().numpy(), loss_i.detach().numpy(), "float64", f"{case} member {i} loss")
        for k, p in alone.named_parameters():
            if p.grad is None:   # the LNN's last bias: the loss does not reach it, stacked or alone
                assert grads[k] is None, k
                continue
            assert_rel(grads[k][i].numpy(), p.grad.numpy(), "float64", f"{case} member {i} d/d{k}")
    assert int(n_bad) == total_bad
    if case == "lnn_relu_falls_back":   # a zero velocity Hessian everywhere: every sample takes pinv
        assert total_bad == K * 12


def test_kinds_whose_maths_is_not_written_for_members_are_refused():
    spec = ModelSpec(kind="hnn", dof=2, hidden=(8, 8), dtype="float64")
    assert not lagbench.models.torch.stacks(spec)
    with pytest.raises(ValueError, match="does not take stacked members"):
        lagbench.models.torch.build_stacked(spec, [init_params(spec, seed=0)])
    paper = ModelSpec(kind="lnn", dof=2, hidden=(8, 8), dtype="float64", formulation="paper")
    assert not lagbench.models.torch.stacks(paper)
