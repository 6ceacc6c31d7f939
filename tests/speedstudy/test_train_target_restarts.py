"""The train-to-target "restarts" protocol: scouts are plain runs of their seeds, the one with the lowest
training loss is continued, and the budget counts every scout's samples."""
import numpy as np
import pytest

from lagbench.models import ModelSpec
from lagbench.replication.claims.double_pendulum import MODELS
from lagbench.replication.training import scouting
from lagbench.replication.training.schedules import learning_rate
from lagbench.replication.training.spike_guard import SpikeGuard
from lagbench.speedstudy import target_loop as TL
from lagbench.speedstudy import train_target as TT


@pytest.fixture(scope="module")
def restarts():
    entry = TT.protocols(4096, 64)["restarts"]
    entry = entry._replace(protocol=entry.protocol.replace(**{"scouting.count": 3}))
    lnn = next(m for m in MODELS if m.label == "lnn")
    spec = ModelSpec(dof=2, hidden=(8, 8), dtype=entry.protocol.dtype, **{**lnn.spec, **entry.overrides})
    log, model = TL.run_protocol("restarts", spec, entry.protocol)
    return entry, spec, log, model


def test_scouts_are_plain_runs_of_their_seeds(restarts):
    entry, spec, log, _ = restarts
    scout = scouting.scout_protocol(entry.protocol)
    ends = [r for r in log if r["phase"] == "scout" and r["step"] > 0]
    assert [r["seed"] for r in ends] == [0, 1, 2]
    for r in ends:
        alone, _ = TL.run_protocol("x", spec, scout, seed=r["seed"])
        assert alone[-1]["heldout_l1"] == pytest.approx(r["heldout_l1"], rel=1e-6)


def test_the_lowest_training_loss_is_continued_and_every_sample_counts(restarts):
    entry, _, log, _ = restarts
    ends = [r for r in log if r["phase"] == "scout" and r["step"] > 0]
    chosen = min(ends, key=lambda r: r["scout_loss"])["seed"]
    cont = [r for r in log if r["phase"] == "continue"]
    assert cont and {r["seed"] for r in cont} == {chosen}
    samples = [r["samples"] for r in log]
    assert samples == sorted(samples) and samples[-1] == scouting.budget_samples(entry.protocol)
    assert ends[-1]["samples"] == 3 * scouting.scout_steps(entry.protocol) * entry.protocol.batch


def test_scouting_takes_at_most_half_the_budget():
    for budget in (2048, 5e5, 3e7):
        p = TT.protocols(int(budget), 64)["restarts"].protocol
        n = scouting.scout_steps(p)
        assert 3 <= n and TT.RESTART_SEEDS * n * p.batch <= max(budget / 2, TT.RESTART_SEEDS * 3 * p.batch)
        assert scouting.budget_samples(p) == max(int(budget) // p.batch, TT.RESTART_SEEDS * n + 1) * p.batch
    p = TT.protocols(int(3e7), 64)["restarts"].protocol
    assert scouting.scout_steps(p) * p.batch == pytest.approx(TT.SCOUT_SAMPLES, abs=p.batch)


def test_summary_names_the_chosen_seed(restarts):
    entry, spec, log, _ = restarts
    rows = TT.summarise("restarts", entry.description, spec, entry.protocol, log)
    assert {r["seed"] for r in rows} == {log[-1]["seed"]}
    assert np.isfinite(rows[0]["best_l1"])


def test_a_scout_that_fails_is_logged_and_never_chosen(monkeypatch):
    """The second scout's first loss is non-finite: it stops there with a row of its own (scout_loss inf),
    and the first scout's row keeps its own loss."""
    entry = TT.protocols(2048, 64)["restarts"]
    lnn = next(m for m in MODELS if m.label == "lnn")
    spec = ModelSpec(dof=2, hidden=(8,), dtype=entry.protocol.dtype, **{**lnn.spec, **entry.overrides})
    calls = {"k": 0}
    real = SpikeGuard.fails

    def fails(self, loss, gnorm):   # the scouts step together: the second call is the second scout's first step
        calls["k"] += 1
        return calls["k"] == 2 or real(self, loss, gnorm)
    monkeypatch.setattr(SpikeGuard, "fails", fails)
    log, _ = TL.run_protocol("r", spec, entry.protocol.replace(**{"scouting.count": 2}))
    ends = [r for r in log if "scout_loss" in r]
    assert [r["seed"] for r in ends] == [0, 1] and np.isfinite(ends[0]["scout_loss"])
    assert ends[1]["scout_loss"] == np.inf and "stopped" in ends[1]["phase"]
    assert {r["seed"] for r in log if r["phase"] == "continue"} == {0}


def test_the_halved_restarts_scout_twice_the_inits_and_count_every_sample():
    """restarts_halved: 16 scouts, the 4 lowest at the cut go on; its budget counts both parts, and it spends
    at most the budget it is given (the continuation takes what the scouts leave)."""
    for budget in (4096, 3e7):
        p = TT.protocols(int(budget), 64)["restarts_halved"].protocol
        assert (p.scouting.count, p.scouting.keep) == (TT.HALVED_SEEDS, TT.HALVED_KEEP)
        parts = scouting.scout_parts(p)
        assert parts[0][0] == TT.HALVED_SEEDS and parts[-1][0] == TT.HALVED_KEEP
        if budget == 3e7:
            assert scouting.budget_samples(p) <= budget
    entry = TT.protocols(4096, 64)["restarts_halved"]
    lnn = next(m for m in MODELS if m.label == "lnn")
    spec = ModelSpec(dof=2, hidden=(8,), dtype=entry.protocol.dtype, **{**lnn.spec, **entry.overrides})
    log, _ = TL.run_protocol("restarts_halved", spec, entry.protocol)
    scouts = [r for r in log if r["phase"].startswith("scout") and r["step"] > 0]
    assert len(scouts) == TT.HALVED_SEEDS
    assert log[-1]["phase"] == "continue" and log[-1]["samples"] == scouting.budget_samples(entry.protocol)
    assert sum(np.isinf(r["scout_loss"]) for r in scouts) == TT.HALVED_SEEDS - TT.HALVED_KEEP   # left at the cut
    cut_lr = learning_rate(scouting.scout_protocol(entry.protocol), scouting.cut_step(entry.protocol) - 1)
    assert all(r["lr"] == cut_lr for r in scouts if np.isinf(r["scout_loss"]))   # their row: where they stopped
    assert log[-1]["seed"] == min(scouts, key=lambda r: r["scout_loss"])["seed"]


def test_the_full_profiles_double_pendulum_trains_what_restarts_halved_measured():
    """full's claims 1-2 train what restarts_halved trains at FULL_SAMPLES (4e7): the same protocol, but for
    full's fallback (`Scouting.fallback`), which acts only where a continuation loses its scout's loss."""
    from lagbench.replication.claims.double_pendulum import FULL_SAMPLES, PROTOCOLS, VELOCITY_SCALE
    full = PROTOCOLS["full"]
    entry = TT.protocols(FULL_SAMPLES, full.data.n_heldout)["restarts_halved"]
    assert full.scouting.fallback == 3 and entry.protocol.scouting.fallback == 0
    logging_only = {"log_every": 1, "tracking": None, "scouting.fallback": 0}
    assert full.schedule.kind == "onecycle"
    assert full.replace(**logging_only) == entry.protocol.replace(**logging_only)
    assert scouting.scouting_samples(full) + full.steps * full.batch <= FULL_SAMPLES
    assert entry.overrides.get("input_scale") == VELOCITY_SCALE["quick"]["input_scale"]
