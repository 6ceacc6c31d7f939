"""Restarts over initialisations as a protocol option (`Protocol.scouts`, `replication.training.scouting`)."""
import numpy as np
import pytest
from parity_kit import Recorder
from parity_rows import BY_NAME

from models import init_params
from replication.training import scouting
from replication.training.data import BatchStream
from replication.training.protocol import Protocol

# the parity table's scouted row (JAX against PyTorch there), longer: the same compiled steps
SPEC = BY_NAME["lnn_scouted"].spec
PROTOCOL = BY_NAME["lnn_scouted"].protocol.replace(steps=60, log_every=5)


@pytest.fixture(scope="module")
def runs():
    return {"jax": scouting.train_scouted(Recorder("jax"), SPEC, PROTOCOL, seed=1)}


def test_the_lowest_tail_is_continued_and_every_step_counts(runs):
    out = runs["jax"]
    rec = out.scouting
    assert rec["init_seeds"] == [4, 5, 6, 7] and rec["scout_steps"] == 10
    assert rec["chosen"] == rec["init_seeds"][int(np.argmin(rec["tail_loss"]))]
    assert out.failure is None and out.steps_done == 4 * 10 + PROTOCOL.steps
    assert out.samples == scouting.budget_samples(PROTOCOL) == 4 * 10 * 8 + 60 * 16
    # the log counts in continuation steps (the scouts' 320 samples are 20 steps of 16)
    assert out.log[0]["step"] == 20 and out.log[-1]["step"] == 20 + PROTOCOL.steps - 1


def test_the_run_is_its_scout_then_a_plain_continuation(runs):
    """Re-done by hand: the chosen init alone for the scout's steps, then the continuation protocol from
    its weights on the continuation's stream: the same weights."""
    rec = runs["jax"].scouting
    s = rec["chosen"]
    scout = scouting.scout_protocol(PROTOCOL)
    assert (scout.batch, scout.lr, scout.steps, scout.scouts) == (8, 3e-3, 10, 0)
    alone = Recorder("jax").train(SPEC, init_params(SPEC, seed=s), scout, BatchStream(scout, s))
    rest = scouting.continuation_protocol(PROTOCOL)
    assert rest.steps == 60 and rest.batch == 16 and rest.lr == PROTOCOL.lr and rest.scouts == 0
    then = Recorder("jax").train(SPEC, alone.params, rest, BatchStream(rest, s + scouting.CONTINUATION_STREAM))
    for k in then.params:
        np.testing.assert_allclose(runs["jax"].params[k], then.params[k], rtol=1e-9, atol=1e-12)


def test_a_failed_scout_is_never_chosen():
    assert scouting.choose([3.0, float("inf"), 1.0]) == 2
    assert scouting.choose([float("inf")] * 3) is None


def test_protocol_checks_and_keys():
    with pytest.raises(ValueError, match="scouts"):
        PROTOCOL.replace(scouts=-1)
    with pytest.raises(ValueError, match="scout_batch"):
        PROTOCOL.replace(scout_batch=65)
    with pytest.raises(ValueError, match="scout_lr"):
        PROTOCOL.replace(scout_lr=float("nan"))
    plain = PROTOCOL.replace(scouts=0, scout_steps=0, scout_batch=0, scout_lr=0.0)
    assert "scouts" not in plain.to_dict() and "scout_steps" not in plain.to_dict()
    assert PROTOCOL.key() != plain.key()
    assert Protocol.from_dict(PROTOCOL.to_dict()) == PROTOCOL


def test_scouts_and_continuation_start_their_one_cycles_apart():
    """scout_lr_start sets the scouts' starting phase (0: the protocol's lr_start); the continuation starts at
    lr_start, so it can warm up from below the rate a fresh Adam would be thrown by."""
    from replication.training.schedules import learning_rate

    p = PROTOCOL.replace(schedule="onecycle", lr=1e-2, lr_start=0.1, scout_lr=1e-3, scout_lr_start=0.2)
    scout, rest = scouting.scout_protocol(p), scouting.continuation_protocol(p)
    assert (scout.lr_start, rest.lr_start, scout.scout_lr_start, rest.scout_lr_start) == (0.2, 0.1, 0.0, 0.0)
    assert learning_rate(rest, 0) < learning_rate(p.replace(lr_start=0.2), 0) / 3
    assert scouting.scout_protocol(p.replace(scout_lr_start=0.0)).lr_start == 0.1
    # 0 is left out of the key, so protocols written before the field keep theirs
    assert "scout_lr_start" not in PROTOCOL.to_dict() and "scout_lr_start" in p.to_dict()
    for bad in (1.0, -0.1, float("nan")):
        with pytest.raises(ValueError, match="scout_lr_start"):
            PROTOCOL.replace(scout_lr_start=bad)
        with pytest.raises(ValueError, match="lr_start"):
            PROTOCOL.replace(lr_start=bad)
