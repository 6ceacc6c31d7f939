"""A training killed mid-way resumes from its snapshot and ends bit for bit where the uninterrupted one
does (`replication.training.snapshots`, `loop.train_members(snapshot=...)`), through `train_cached`, the
path every unit takes: one model (with the held-out tracker), a cohort, and a scouted run killed in either
phase, both frameworks, float64 and float32."""
import json
import logging

import numpy as np
import pytest
from parity_rows import GUARDED, LNN

from lagbench.replication.training import snapshots
from lagbench.replication.training.protocol import Scouting, Tracking
from lagbench.replication.training.schedules import OneCycle
from lagbench.replication.training.train import train_cached, train_key

SPEC = LNN                                            # the chaotic double-pendulum LNN: any drift would show
ONE = GUARDED.replace(steps=30, tracking=Tracking(every=5, keep=True))   # guard acting often, tracking, kept checkpoints
COHORT = GUARDED.replace(steps=24, batch=8, cohort=3)
SCOUTED = GUARDED.replace(scouting=Scouting(count=3, steps=8, batch=8, schedule=OneCycle(lr=3e-3, start=GUARDED.schedule.start)), steps=16)
SCOUTED_CUT = SCOUTED.replace(**{"scouting.keep": 2})           # 3 scouts to step 4, the 2 lowest on to 8
TIMING = {"wall_s", "train_s"}                        # clocks: the only columns allowed to differ


class Killed(Exception):
    pass


def _killer(at: int):
    """on_log that raises at its `at`-th call (0-based): a run killed in the middle of a step."""
    calls = []

    def on_log(row):
        calls.append(row["step"])
        if len(calls) == at + 1:
            raise Killed
    on_log.calls = calls
    return on_log


@pytest.fixture(autouse=True)
def every_step(monkeypatch):
    monkeypatch.setattr(snapshots, "SNAPSHOT_EVERY_S", 0.0)   # a snapshot after every step


def _same(a, b):
    for k in a.params:
        assert np.array_equal(a.params[k], b.params[k]), k
    assert len(a.log) == len(b.log)
    for ra, rb in zip(a.log, b.log, strict=True):
        keys = set(ra) - TIMING
        assert keys == set(rb) - TIMING
        differ = [k for k in keys if not (ra[k] == rb[k] or (np.isnan(ra[k]) and np.isnan(rb[k])))]
        assert not differ, (ra["step"], differ)
    assert (a.tracked is None) == (b.tracked is None)
    for k in a.tracked or {}:
        assert np.array_equal(a.tracked[k], b.tracked[k]), k
    assert (a.failure, a.steps_done, a.samples, a.scouting, a.skipped_steps) == \
        (b.failure, b.steps_done, b.samples, b.scouting, b.skipped_steps)


def _resumed(tmp_path, fw, spec, protocol, seed, at):
    """(uninterrupted, killed-then-resumed outcome, the resumed run's logged steps)."""
    ref = train_cached(tmp_path / "ref", fw, spec, protocol, seed)
    with pytest.raises(Killed):
        train_cached(tmp_path / "cut", fw, spec, protocol, seed, on_log=_killer(at))
    inflight = list((tmp_path / "cut" / "trained" / fw).glob("*/inflight/*.json"))
    assert inflight, "no snapshot was left by the killed run"
    again = _killer(10 ** 9)
    out = train_cached(tmp_path / "cut", fw, spec, protocol, seed, on_log=again)
    assert not list((tmp_path / "cut" / "trained").rglob("inflight")), "snapshots left after the training stored"
    return ref, out, again.calls


@pytest.mark.parametrize("fw", ["jax", "torch"])
def test_one_model_resumes_bit_for_bit(tmp_path, fw):
    ref, out, steps = _resumed(tmp_path, fw, SPEC, ONE, 2, at=17)
    _same(ref, out)
    assert steps[0] == 17, "the resumed run started over instead of going on from its snapshot"
    assert [r["step"] for r in out.log if "heldout_loss" in r] == [0, 5, 10, 15, 20, 25, 29]
    assert ref.skipped_steps > 0   # the guard acted, so its restored history mattered
    assert list(out.tracked["step"]) == [0, 5, 10, 15, 20, 25, 29]   # the kept checkpoints survive the kill
    for k in ref.params:
        assert np.array_equal(out.tracked[f"p/{k}"][-1], ref.params[k])   # the last one is the final model
    cached = train_cached(tmp_path / "ref", fw, SPEC, ONE, 2)   # and come back from the cache
    assert all(np.array_equal(cached.tracked[k], ref.tracked[k]) for k in ref.tracked)


@pytest.mark.parametrize("fw", ["jax", "torch"])
def test_a_cohort_resumes_bit_for_bit(tmp_path, fw):
    ref, out, steps = _resumed(tmp_path, fw, SPEC, COHORT, 4, at=11)
    _same(ref, out)
    assert steps[0] == 11
    # the other seeds of the cohort were stored by the same resumed program
    for seed in (3, 5):
        _same(train_cached(tmp_path / "ref", fw, SPEC, COHORT, seed), train_cached(tmp_path / "cut", fw, SPEC, COHORT, seed))


@pytest.mark.parametrize(("fw", "at"), [("jax", 5), ("jax", 12), ("torch", 12)])
def test_a_scouted_run_resumes_in_either_phase(tmp_path, fw, at):
    """at 5: killed among the scouts (8 logged steps); at 12: in the continuation, which must not scout again."""
    ref, out, steps = _resumed(tmp_path, fw, SPEC, SCOUTED, 1, at=at)
    _same(ref, out)
    if at >= SCOUTED.scouting.steps:
        assert len(steps) == SCOUTED.steps - (at - SCOUTED.scouting.steps), "the scouts were trained again"


@pytest.mark.parametrize(("fw", "at"), [("jax", 2), ("jax", 6), ("jax", 10), ("torch", 6)])
def test_a_scouted_run_with_a_cut_resumes_in_any_part(tmp_path, fw, at):
    """at 2: before the cut; at 6: among the kept scouts (which must not scout the first half again);
    at 10: in the continuation."""
    ref, out, steps = _resumed(tmp_path, fw, SPEC, SCOUTED_CUT, 1, at=at)
    _same(ref, out)
    assert ref.scouting["kept"] and ref.scouting["chosen"] in ref.scouting["kept"]
    if at >= 4:
        assert steps[0] >= 4, "the first half of the scouts was trained again"


@pytest.mark.parametrize("fw", ["jax", "torch"])
def test_float32_resumes_bit_for_bit(tmp_path, fw):
    import dataclasses
    spec = dataclasses.replace(SPEC, dtype="float32")
    ref, out, steps = _resumed(tmp_path, fw, spec, ONE.replace(dtype="float32", steps=20), 0, at=9)
    _same(ref, out)


def _only_snapshot(tmp_path, fw, protocol, seed):
    [path] = (tmp_path / "cut" / "trained" / fw).glob("*/inflight/run.json")
    return path


def test_a_damaged_or_foreign_snapshot_is_not_used(tmp_path, caplog):
    protocol = ONE.replace(tracking=None, steps=12)
    ref = train_cached(tmp_path / "ref", "torch", SPEC, protocol, 0)
    with pytest.raises(Killed):
        train_cached(tmp_path / "cut", "torch", SPEC, protocol, 0, on_log=_killer(6))
    path = _only_snapshot(tmp_path, "torch", protocol, 0)
    meta = json.loads(path.read_text())
    assert meta["key"] == train_key("torch", SPEC, protocol, 0) and meta["step"] == 6
    path.write_text(path.read_text().replace('"step": 6', '"step": 2'))   # checksum no longer matches
    calls = _killer(10 ** 9)
    with caplog.at_level(logging.WARNING, logger="lagbench"):
        out = train_cached(tmp_path / "cut", "torch", SPEC, protocol, 0, on_log=calls)
    assert "not used, starting over" in caplog.text and "checksum" in caplog.text
    assert calls.calls[0] == 0
    _same(ref, out)


def test_a_snapshot_of_another_training_is_not_used(tmp_path, caplog):
    from lagbench.replication.training.snapshots import Snapshots
    protocol = ONE.replace(tracking=None, steps=12)
    with pytest.raises(Killed):
        train_cached(tmp_path / "cut", "jax", SPEC, protocol, 0, on_log=_killer(6))
    path = _only_snapshot(tmp_path, "jax", protocol, 0)
    other = Snapshots(path.parent, "another-key")
    with caplog.at_level(logging.WARNING, logger="lagbench"):
        assert other.load(1, protocol.steps) is None
    assert "made by another run" in caplog.text
    assert Snapshots(path.parent, train_key("jax", SPEC, protocol, 0)).load(1, protocol.steps + 1) is None


def test_a_failed_snapshot_write_does_not_stop_the_training(tmp_path, caplog):
    from lagbench.replication.training.snapshots import Snapshots
    (tmp_path / "file").write_text("x")
    store = Snapshots(tmp_path / "file" / "inflight", "k")    # a folder that cannot be made
    with caplog.at_level(logging.WARNING, logger="lagbench"):
        store.save({"step": 1}, {"a": np.zeros(2)})
    assert "not written" in caplog.text
