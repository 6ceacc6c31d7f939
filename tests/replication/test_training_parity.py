"""JAX and PyTorch training from identical float64 weights: loss and gradient norm agree at every step."""
import numpy as np
import pytest

from models import ModelSpec
from replication.protocol import Protocol
from replication.training import run_training

CASES = {
    "lnn": (ModelSpec(kind="lnn", dof=2, hidden=(16, 16), dtype="float64", angle_wrap=True),
            Protocol(data="double_pendulum_iid", steps=20, batch=16, n_train=64, dtype="float64", log_every=1,
                     resample=True)),
    # the spike guard on (clip far below the gradient norms, skip at the median): the same steps are clipped
    # and skipped in both frameworks
    "lnn_guarded": (ModelSpec(kind="lnn", dof=2, hidden=(16, 16), dtype="float64", angle_wrap=True),
                    Protocol(data="double_pendulum_iid", steps=40, batch=16, n_train=64, dtype="float64",
                             log_every=1, resample=True, grad_clip=30.0, spike_skip=1.0)),
    "hnn_qp": (ModelSpec(kind="hnn", dof=1, hidden=(16, 16), dtype="float64", activation="tanh", init="xavier"),
               Protocol(data="spring_iid", task="hamiltonian", coords="qp", loss="mse", steps=20, batch=16,
                        n_train=64, dtype="float64", log_every=1)),
    "delan": (ModelSpec(kind="delan", dof=2, hidden=(16, 16), dtype="float64", init="xavier"),
              Protocol(data="two_link_arm", task="inverse_dynamics", loss="mse", steps=20, batch=16, n_train=400,
                       dtype="float64", log_every=1, l2=1e-5, schedule="constant")),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_twenty_steps_agree(case):
    spec, protocol = CASES[case]
    a = run_training("jax", spec, protocol, seed=3)
    b = run_training("torch", spec, protocol, seed=3)
    assert a.failure is None and b.failure is None
    assert len(a.log) == len(b.log) == protocol.steps
    for ra, rb in zip(a.log, b.log, strict=True):
        assert ra["step"] == rb["step"] and ra["lr"] == rb["lr"]
        np.testing.assert_allclose(ra["loss"], rb["loss"], rtol=1e-8, err_msg=f"loss at step {ra['step']}")
        np.testing.assert_allclose(ra["grad_norm"], rb["grad_norm"], rtol=1e-8, err_msg=f"grad at step {ra['step']}")
        assert ra.get("skipped_steps") == rb.get("skipped_steps"), f"skipped steps differ at step {ra['step']}"
    for k in a.params:
        np.testing.assert_allclose(a.params[k], b.params[k], rtol=1e-7, atol=1e-10, err_msg=k)


def test_guard_changes_the_run():
    """The guarded case really clips and skips: steps are skipped, and the weights differ from the unguarded run."""
    spec, protocol = CASES["lnn_guarded"]
    guarded = run_training("jax", spec, protocol, seed=3)
    plain = run_training("jax", spec, protocol.replace(grad_clip=0.0, spike_skip=0.0), seed=3)
    assert 0 < guarded.log[-1]["skipped_steps"] < protocol.steps
    assert "skipped_steps" not in plain.log[-1]
    assert any(not np.allclose(guarded.params[k], plain.params[k]) for k in plain.params)
