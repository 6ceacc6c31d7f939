"""Rollback on a loss blow-up (`Protocol.rollback`, `replication.training.rollback`)."""
import numpy as np
import pytest
from parity_rows import BY_NAME

from models import init_params
from replication.training import scouting, train_jax, train_torch
from replication.training.data import BatchStream
from replication.training.rollback import WINDOW, Rollback

ROW = BY_NAME["lnn_scouted"]
PROTOCOL = ROW.protocol.replace(scouts=0, scout_steps=0, scout_batch=0, scout_lr=0.0)


class FakeStepper:
    """A 'model' whose state is the number of steps it took since its last restore."""

    def __init__(self):
        self.state, self.loads = np.zeros(1), []

    def step(self):
        self.state = self.state + 1

    def state_arrays(self):
        return [self.state]

    def load_state_arrays(self, arrays):
        self.loads.append(float(arrays[0][0]))
        self.state = arrays[0].copy()


def _run(hook, stepper, losses, start=0):
    for k, loss in enumerate(losses, start):
        stepper.step()
        hook(k, stepper, {"loss": np.array([loss])})


def test_a_blown_up_window_puts_back_the_best_windows_state():
    hook, stepper = Rollback(PROTOCOL.replace(rollback=2.5)), FakeStepper()
    # three windows that improve (the best is the third: its state is 3 * WINDOW steps), one at 2x (kept),
    # one at 3x the best (put back)
    _run(hook, stepper, [4.0] * WINDOW + [2.0] * WINDOW + [1.0] * WINDOW + [2.0] * WINDOW + [3.0] * WINDOW)
    assert hook.best == 1.0 and hook.rollbacks == 1 and stepper.loads == [3 * WINDOW]
    assert stepper.state[0] == 3 * WINDOW
    # the saved state is a copy: the model going on does not change it
    _run(hook, stepper, [1.5] * WINDOW, start=5 * WINDOW)
    assert hook.saved[0][0] == 3 * WINDOW and stepper.state[0] == 4 * WINDOW


def test_nothing_is_put_back_while_the_loss_stays_within_the_factor():
    hook, stepper = Rollback(PROTOCOL.replace(rollback=2.5)), FakeStepper()
    rng = np.random.default_rng(0)
    _run(hook, stepper, list(np.exp(rng.normal(0, 0.3, 20 * WINDOW))))   # noisy, no trend: window means ~1
    assert hook.rollbacks == 0 and stepper.loads == []


def test_the_hooks_state_survives_a_snapshot():
    hook, stepper = Rollback(PROTOCOL.replace(rollback=2.0)), FakeStepper()
    _run(hook, stepper, [1.0] * WINDOW + [0.5] * (WINDOW // 2))
    meta, arrays = hook.snapshot_state()
    again = Rollback(PROTOCOL.replace(rollback=2.0))
    again.restore_snapshot(meta, arrays)
    assert (again.best, again.losses, again.rollbacks) == (hook.best, hook.losses, hook.rollbacks)
    np.testing.assert_array_equal(again.saved[0], hook.saved[0])
    empty = Rollback(PROTOCOL.replace(rollback=2.0))
    empty.restore_snapshot(*Rollback(PROTOCOL.replace(rollback=2.0)).snapshot_state())
    assert empty.saved is None and empty.best == np.inf


def test_protocol_checks_scouts_and_members():
    for bad in (1.0, 0.5, -1.0, float("nan"), float("inf")):
        with pytest.raises(ValueError, match="rollback"):
            PROTOCOL.replace(rollback=bad)
    with pytest.raises(ValueError, match="rollback"):
        PROTOCOL.replace(rollback=3.0, cohort=2)
    assert "rollback" not in PROTOCOL.to_dict() and PROTOCOL.replace(rollback=3.0).key() != PROTOCOL.key()
    scouted = ROW.protocol.replace(rollback=3.0)
    assert scouting.scout_protocol(scouted).rollback == 0 and scouting.continuation_protocol(scouted).rollback == 3.0
    spec = ROW.spec
    p = PROTOCOL.replace(rollback=3.0, steps=2)
    with pytest.raises(ValueError, match="rollback"):
        train_jax.train_members(spec, [init_params(spec, seed=s) for s in (0, 1)], p,
                                [BatchStream(p, s) for s in (0, 1)])


@pytest.mark.parametrize("module", [train_jax, train_torch], ids=["jax", "torch"])
def test_a_rollback_that_never_fires_changes_no_number(module):
    """The hook only reads the loss until it fires: with a factor no window reaches, the run is the plain one."""
    spec, p = ROW.spec, PROTOCOL.replace(steps=2 * WINDOW + 5, log_every=10)
    plain = module.train(spec, init_params(spec, seed=2), p, BatchStream(p, 2))
    guarded = module.train(spec, init_params(spec, seed=2), p.replace(rollback=1e9), BatchStream(p, 2))
    for k in plain.params:
        np.testing.assert_array_equal(plain.params[k], guarded.params[k])
    assert [r["loss"] for r in plain.log] == [r["loss"] for r in guarded.log]

