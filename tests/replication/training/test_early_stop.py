"""Early stopping (`Protocol.early_stop`, `replication.training.early_stop`): a run ends at the evaluation that
makes `patience` in a row without a new best by `min_improvement`, keeping the last step's parameters; a
restarts' protocol stops its continuation only; no claim's protocol has it, and a protocol without it keeps
its key."""
import math

import numpy as np
import pytest
from parity_rows import BY_NAME

from lagbench.replication.training import early_stop, scouting
from lagbench.replication.training.protocol import EarlyStop, Protocol
from lagbench.replication.training.schedules import Constant, learning_rate
from lagbench.replication.training.train import run_training

SPEC = BY_NAME["lnn_scouted"].spec   # a small float64 double-pendulum LNN
PLAIN = scouting.scout_protocol(BY_NAME["lnn_scouted"].protocol).replace(steps=40, log_every=2)


class _Params:
    def params(self):
        return {}


def _stops(losses, patience, min_improvement, monkeypatch) -> tuple[int | None, dict]:
    """Feeds the hook one held-out loss per evaluation (every step); the step it stops after and its record."""
    seq = iter(losses)
    monkeypatch.setattr(early_stop, "data_loss", lambda *a: next(seq))
    monkeypatch.setattr(early_stop.datamod, "heldout", lambda p: {"target": np.zeros((3, 1))})
    p = PLAIN.replace(steps=len(losses) + 1, log_every=1,
                      early_stop=EarlyStop(every=1, patience=patience, min_improvement=min_improvement))
    hook = early_stop.EarlyStopper("jax", SPEC, p)
    for k in range(len(losses)):
        if hook(k, _Params(), {}):
            return k, hook.record()
    return None, hook.record()


def test_the_rule_counts_evaluations_without_a_new_best_by_the_least_improvement(monkeypatch):
    # 0.995 is below 1.0 but not by 1 %: no new best; 0.98 is; then three without one
    k, rec = _stops([1.0, 0.995, 0.98, 0.975, 0.99, 0.979, 0.5], patience=3, min_improvement=0.01, monkeypatch=monkeypatch)
    assert k == 5 and rec["stopped_at"] == 5 and rec["best_step"] == 2 and rec["best_heldout_loss"] == 0.98
    assert rec["evaluations"] == 6 and rec["last_heldout_loss"] == 0.979
    # with no least improvement every lower value is a best: it never waits three
    assert _stops([1.0, 0.995, 0.98, 0.975, 0.99, 0.979, 0.5], 3, 0.0, monkeypatch)[0] is None
    # a non-finite value is never a best
    k, rec = _stops([1.0, math.nan, math.inf, 0.9, 2.0, 2.0, 2.0], 2, 0.01, monkeypatch)
    assert k == 2 and rec["best_step"] == 0


def test_a_run_stops_when_its_heldout_error_stops_improving_and_keeps_its_last_step():
    """At a rate too small to move the model the held-out loss cannot improve: the run ends after `patience`
    evaluations past the first, with the parameters of a run of that many steps."""
    still = PLAIN.replace(schedule=Constant(lr=1e-12))
    out = run_training("jax", SPEC, still.replace(early_stop=EarlyStop(every=4, patience=3)), 1)
    assert out.early_stop["stopped_at"] == 12 and out.steps_done == 13 and out.early_stop["best_step"] == 0
    assert [r["step"] for r in out.log if "heldout_loss" in r] == [0, 4, 8, 12]
    short = run_training("jax", SPEC, still.replace(steps=13), 1)
    for name in short.params:
        np.testing.assert_array_equal(out.params[name], short.params[name])
    full = run_training("jax", SPEC, PLAIN.replace(early_stop=EarlyStop(every=4, patience=100)), 1)
    assert full.early_stop["stopped_at"] is None and full.steps_done == PLAIN.steps


def test_a_stopped_run_anneals_from_its_exact_state(monkeypatch):
    """The held-out loss never improves (stubbed): the run stops after step 12 and goes on for `anneal` steps
    from its exact state. At a constant rate that is one run of 12 + 1 + 5 steps; under a one-cycle the rate
    falls from the schedule's at step 13 to its final rate."""
    monkeypatch.setattr(early_stop, "data_loss", lambda *a: 1.0)
    rule = EarlyStop(every=4, patience=3, anneal=5)
    constant = PLAIN.replace(schedule=Constant(lr=1e-3))
    out = run_training("jax", SPEC, constant.replace(early_stop=rule), 1)
    assert out.early_stop["stopped_at"] == 12 and out.steps_done == 18 and [r["step"] for r in out.log][-1] == 17
    whole = run_training("jax", SPEC, constant.replace(steps=18), 1)
    for name in whole.params:
        np.testing.assert_array_equal(out.params[name], whole.params[name])
    cycle = run_training("jax", SPEC, PLAIN.replace(early_stop=rule), 1)
    lrs = {r["step"]: r["lr"] for r in cycle.log}
    start, end = learning_rate(PLAIN, 13), learning_rate(PLAIN, PLAIN.steps)
    assert lrs[14] == pytest.approx(end + (start - end) * (1 + math.cos(math.pi / 5)) / 2)
    assert lrs[12] == learning_rate(PLAIN, 12) and start > lrs[14] > lrs[16] > end


def test_a_scouted_run_stops_its_continuation_only():
    p = BY_NAME["lnn_scouted"].protocol.replace(steps=30, log_every=2, schedule=Constant(lr=1e-12))
    off = run_training("jax", SPEC, p, 0)
    on = run_training("jax", SPEC, p.replace(early_stop=EarlyStop(every=2, patience=2)), 0)
    assert on.scouting == off.scouting   # the scouts train and are chosen as without it
    assert on.early_stop["stopped_at"] == 4
    assert on.steps_done == off.steps_done - (p.steps - 5)
    assert scouting.scout_protocol(p.replace(early_stop=EarlyStop(every=2, patience=2))).early_stop is None


def test_no_claim_protocol_stops_early():
    from lagbench.replication.claims import CLAIMS, PROFILES
    from lagbench.replication.claims.resolved import resolved

    for claim in CLAIMS.values():
        for profile in PROFILES:
            for m in resolved(claim, profile).models:
                assert m.protocol.early_stop is None, (claim.id, profile, m.label)
                assert "early_stop" not in m.protocol.to_dict()


def test_a_protocol_stores_its_early_stop_only_when_it_has_one():
    with_it = PLAIN.replace(early_stop=EarlyStop(every=4, patience=3))
    assert "early_stop" not in PLAIN.to_dict() and with_it.key() != PLAIN.key()
    assert Protocol.from_dict(with_it.to_dict()) == with_it and Protocol.from_dict(PLAIN.to_dict()) == PLAIN
    with pytest.raises(ValueError, match="early stop every 3 is not a multiple of log_every 2"):
        PLAIN.replace(early_stop=EarlyStop(every=3, patience=1))
    with pytest.raises(ValueError, match="cohort 2 with early_stop"):
        PLAIN.replace(cohort=2, early_stop=EarlyStop(every=2, patience=1))
    with pytest.raises(ValueError, match="early stop patience must be an integer >= 1"):
        EarlyStop(every=2, patience=0)
