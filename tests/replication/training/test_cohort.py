"""Seeds trained side by side (`Protocol.cohort`): each seed's run equals its run alone, and the training
cache holds every member, so the cohort's other units train nothing."""
import numpy as np
import pytest
from parity_rows import BY_NAME

from lagbench.replication.training import scouting
from lagbench.replication.training import train as training
from lagbench.replication.training.protocol import Data, Protocol, Scouting
from lagbench.replication.training.schedules import OneCycle

SPEC = BY_NAME["lnn_scouted"].spec   # a small float64 double-pendulum LNN
PROTOCOL = scouting.scout_protocol(BY_NAME["lnn_scouted"].protocol).replace(steps=8, log_every=1, cohort=2)


def test_a_cohort_trains_each_seed_as_alone_and_caches_every_member(tmp_path, monkeypatch):
    assert SPEC.dtype == "float64" and training.cohort_seeds(PROTOCOL, 3) == [2, 3]
    got = training.train_cached(tmp_path, "jax", SPEC, PROTOCOL, seed=3)
    assert got.cohort == {"seeds": [2, 3]} and got.failure is None and got.steps_done == PROTOCOL.steps
    alone = training.run_training("jax", SPEC, PROTOCOL.replace(cohort=None), 3)
    for k in alone.params:
        np.testing.assert_allclose(got.params[k], alone.params[k], rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose([r["loss"] for r in got.log], [r["loss"] for r in alone.log], rtol=1e-9)
    # the other member was stored too: its unit reads it and trains nothing
    def boom(*a, **k):
        raise AssertionError("retrained a cached cohort member")
    monkeypatch.setattr(training, "train_cohort", boom)
    monkeypatch.setattr(training, "run_training", boom)
    other = training.train_cached(tmp_path, "jax", SPEC, PROTOCOL, seed=2)
    assert other.cohort == {"seeds": [2, 3]}
    k0 = next(iter(got.params))   # its own init and batches: other weights
    assert not np.allclose(other.params[k0], got.params[k0])


def test_a_cohort_is_one_chain_and_one_estimate():
    assert training.group_key("jax", SPEC, PROTOCOL, 2) == training.group_key("jax", SPEC, PROTOCOL, 3)
    assert training.group_key("jax", SPEC, PROTOCOL, 3) != training.group_key("jax", SPEC, PROTOCOL, 4)
    alone = PROTOCOL.replace(cohort=None)
    assert training.group_key("jax", SPEC, alone, 3) == training.train_key("jax", SPEC, alone, 3)
    assert alone.to_dict()["cohort"] is None and PROTOCOL.to_dict()["cohort"] == 2


def test_a_cohort_and_scouts_are_refused_together():
    with pytest.raises(ValueError, match="cohort 2 with scouting"):
        Protocol(data=Data("double_pendulum_iid", n_train=4), steps=2, batch=2, cohort=2, scouting=Scouting(count=4, steps=2, batch=2, schedule=OneCycle(lr=1e-3, start=0.2)))
    for bad in (-1, 0, 1):   # one seed at a time is None, not a number
        with pytest.raises(ValueError, match="cohort"):
            Protocol(data=Data("double_pendulum_iid", n_train=4), steps=2, batch=2, cohort=bad)
