"""Restarts over initialisations as a protocol part (`Protocol.scouting`, `replication.training.scouting`)."""
import numpy as np
import pytest
from parity_kit import Recorder
from parity_rows import BY_NAME

from lagbench.models import init_params
from lagbench.replication.training import scouting
from lagbench.replication.training.data import BatchStream
from lagbench.replication.training.protocol import Protocol, Scouting

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
    assert (scout.batch, scout.schedule.lr, scout.steps, scout.scouting) == (8, 3e-3, 10, None)
    alone = Recorder("jax").train(SPEC, init_params(SPEC, seed=s), scout, BatchStream(scout, s))
    rest = scouting.continuation_protocol(PROTOCOL)
    assert rest.steps == 60 and rest.batch == 16 and rest.schedule == PROTOCOL.schedule and rest.scouting is None
    then = Recorder("jax").train(SPEC, alone.params, rest, BatchStream(rest, s + scouting.CONTINUATION_STREAM))
    for k in then.params:
        np.testing.assert_allclose(runs["jax"].params[k], then.params[k], rtol=1e-9, atol=1e-12)


def test_a_failed_scout_is_never_chosen():
    assert scouting.choose([3.0, float("inf"), 1.0]) == 2
    assert scouting.choose([float("inf")] * 3) is None


def test_protocol_checks_and_keys():
    for bad, name in ((1, "count"), (-1, "count")):
        with pytest.raises(ValueError, match=f"scouting {name}"):
            PROTOCOL.replace(**{"scouting.count": bad})
    with pytest.raises(ValueError, match="scouting batch"):
        PROTOCOL.replace(**{"scouting.batch": 65})
    with pytest.raises(ValueError, match="learning rate must be positive"):
        PROTOCOL.replace(**{"scouting.schedule.lr": float("nan")})
    plain = PROTOCOL.replace(scouting=None)
    assert plain.to_dict()["scouting"] is None and PROTOCOL.key() != plain.key()
    with pytest.raises(ValueError, match="has no scouting"):
        plain.replace(**{"scouting.schedule.lr": 1e-3})
    assert Protocol.from_dict(PROTOCOL.to_dict()) == PROTOCOL


def test_scouts_and_continuation_start_their_one_cycles_apart():
    """The scouting's schedule sets the scouts' starting phase; the continuation starts at the protocol's
    schedule's, so it can warm up from below the rate a fresh Adam would be thrown by."""
    from lagbench.replication.training.schedules import OneCycle, learning_rate

    p = PROTOCOL.replace(schedule=OneCycle(lr=1e-2, start=0.1),
                         **{"scouting.schedule": OneCycle(lr=1e-3, start=0.2)})
    scout, rest = scouting.scout_protocol(p), scouting.continuation_protocol(p)
    assert (scout.schedule.start, rest.schedule.start, scout.scouting, rest.scouting) == (0.2, 0.1, None, None)
    assert learning_rate(rest, 0) < learning_rate(p.replace(**{"schedule.start": 0.2}), 0) / 3
    assert scouting.scout_protocol(p.replace(**{"scouting.schedule.start": 0.0})).schedule.start == 0.0
    for bad in (1.0, -0.1, float("nan")):
        with pytest.raises(ValueError, match="one-cycle start"):
            p.replace(**{"scouting.schedule.start": bad})
        with pytest.raises(ValueError, match="one-cycle start"):
            p.replace(**{"schedule.start": bad})


# successive halving (`Scouting.keep`): 4 scouts of 10 steps, the 2 lowest at the cut (step 5) go on
CUT = PROTOCOL.replace(**{"scouting.keep": 2})


class _Steps:
    """A hook that keeps every step's per-member training loss (NaN once a member stopped)."""

    def __init__(self):
        self.rows = []

    def __call__(self, k, stepper, info):
        self.rows.append(np.where(info["live"], info["loss"], np.nan))


@pytest.fixture(scope="module", params=["jax", "torch"])
def cut_and_uncut(request):
    seeds = scouting.init_seeds(CUT, 1)
    seen, rec = _Steps(), {}
    cut = scouting.scout(Recorder(request.param), SPEC, CUT, seeds, record=rec)
    uncut = scouting.scout(Recorder(request.param), SPEC, PROTOCOL, seeds, hooks=(seen,))
    return seeds, cut, uncut, rec, np.asarray(seen.rows)


def test_a_cut_keeps_the_lowest_scouts_and_each_goes_on_as_if_uncut(cut_and_uncut):
    seeds, (cut, tails), (uncut, uncut_tails), rec, steps = cut_and_uncut
    half = scouting.cut_step(CUT)
    assert half == 5 and rec["cut_step"] == 5 and steps.shape == (10, 4)
    # the tails at the cut are the uncut run's over its first 5 steps (5 // 20 -> the last one)
    np.testing.assert_allclose(rec["cut_tail_loss"], steps[half - 1], rtol=1e-12)
    lowest = sorted(np.argsort(steps[half - 1])[:2])
    assert rec["kept"] == [seeds[i] for i in lowest]
    for i in range(4):
        if i in lowest:   # the kept ones: the uncut run's numbers (vmapped over 2 instead of 4, float64)
            assert cut[i].steps_done == 10 and tails[i] == pytest.approx(uncut_tails[i], rel=1e-10)
            for k in cut[i].params:
                np.testing.assert_allclose(cut[i].params[k], uncut[i].params[k], rtol=1e-9, atol=1e-12)
            assert [r["step"] for r in cut[i].log] == [r["step"] for r in uncut[i].log]
            np.testing.assert_allclose([r["loss"] for r in cut[i].log], [r["loss"] for r in uncut[i].log], rtol=1e-10)
        else:             # left behind at the cut: never chosen
            assert cut[i].steps_done == half and tails[i] == float("inf")
    assert scouting.choose(tails) in lowest


def test_a_cut_counts_its_budget():
    assert scouting.scouting_samples(CUT) == (4 * 5 + 2 * 5) * 8
    assert scouting.budget_samples(CUT) == (4 * 5 + 2 * 5) * 8 + 60 * 16
    assert scouting.scouting_samples(PROTOCOL) == 4 * 10 * 8 and scouting.cut_step(PROTOCOL) is None
    out = scouting.train_scouted(Recorder("jax"), SPEC, CUT.replace(steps=6), seed=1)
    assert out.samples == scouting.budget_samples(CUT.replace(steps=6))
    assert out.scouting["chosen"] in out.scouting["kept"] and out.scouting["cut_step"] == 5
    for bad in ({"keep": 4}, {"keep": -1}, {"keep": 2, "steps": 1}):
        with pytest.raises(ValueError, match="keep"):
            Scouting(**{**vars(PROTOCOL.scouting), **bad})
    assert PROTOCOL.scouting.keep is None and CUT.key() != PROTOCOL.key()
    assert scouting.scout_protocol(CUT).scouting is None and scouting.continuation_protocol(CUT).scouting is None


# scouts that barely move (their tail is their init's loss) and continuations at 3e-3 (1e-3 for `SLOW`): on
# seed 2 the first continuation ends below its scout, on seed 1 the second does, on seed 4 at 1e-3 none do
STILL = PROTOCOL.replace(**{"scouting.schedule.lr": 1e-9, "schedule.lr": 3e-3})
SLOW = STILL.replace(**{"schedule.lr": 1e-3})


def _order(rec):
    return [rec["init_seeds"][i] for i in np.argsort(rec["tail_loss"])]


def _scout_tail(rec, init_seed):
    return rec["tail_loss"][rec["init_seeds"].index(init_seed)]


def test_a_continuation_that_keeps_its_scouts_loss_is_the_run_whatever_the_fallbacks():
    """With fallbacks declared, a continuation that ends at or below its scout's tail loss ends the run: the
    same weights and samples as without them; the record names it."""
    plain = scouting.train_scouted(Recorder("jax"), SPEC, STILL, seed=2)
    out = scouting.train_scouted(Recorder("jax"), SPEC, STILL.replace(**{"scouting.fallback": 2}), seed=2)
    rec = out.scouting
    assert "continued" not in plain.scouting and rec["continued"] == [rec["chosen"]] == [plain.scouting["chosen"]]
    assert rec["continuation_tail_loss"][0] <= _scout_tail(rec, rec["chosen"])
    assert out.samples == plain.samples == scouting.budget_samples(STILL) and out.steps_done == plain.steps_done
    for k in out.params:
        np.testing.assert_array_equal(out.params[k], plain.params[k])


@pytest.mark.parametrize("framework", ["jax", "torch"])
def test_a_continuation_that_loses_its_scout_is_followed_by_the_next_scouts(framework):
    """A continuation that ends above its scout's tail loss: the next scout by tail loss is continued; a
    continuation that keeps its scout's loss ends the run; every continuation's samples count; the run's log
    goes on in order; the lowest continuation tail is kept."""
    out = scouting.train_scouted(Recorder(framework), SPEC, STILL.replace(**{"scouting.fallback": 3}), seed=1)
    rec = out.scouting
    first, second = rec["continued"]
    assert [first, second] == _order(rec)[:2]
    assert rec["continuation_tail_loss"][0] > _scout_tail(rec, first)
    assert rec["continuation_tail_loss"][1] <= _scout_tail(rec, second)
    assert rec["chosen"] == rec["continued"][int(np.argmin(rec["continuation_tail_loss"]))]
    assert out.samples == scouting.budget_samples(STILL) + STILL.steps * STILL.batch
    steps = [r["step"] for r in out.log]
    assert steps == sorted(steps) and steps[-1] == scouting.progress_steps(STILL) + STILL.steps - 1


def test_the_fallbacks_stop_at_their_count_and_the_lowest_continuation_is_kept():
    out = scouting.train_scouted(Recorder("jax"), SPEC, SLOW.replace(**{"scouting.fallback": 2}), seed=4)
    rec, tails = out.scouting, out.scouting["continuation_tail_loss"]
    assert rec["continued"] == _order(rec)[:3]
    assert all(t > _scout_tail(rec, s) for s, t in zip(rec["continued"], tails, strict=True))
    assert rec["chosen"] == rec["continued"][int(np.argmin(tails))]
    assert out.samples == scouting.budget_samples(SLOW) + 2 * SLOW.steps * SLOW.batch


def test_fallbacks_are_checked_and_stored_only_when_declared():
    for bad in (-1, 4, 1.5):
        with pytest.raises(ValueError, match="fallback"):
            PROTOCOL.replace(**{"scouting.fallback": bad})
    with pytest.raises(ValueError, match="fallback"):
        CUT.replace(**{"scouting.fallback": 2})   # 2 scouts reach the end: one fallback at most
    assert "fallback" not in PROTOCOL.to_dict()["scouting"]
    more = PROTOCOL.replace(**{"scouting.fallback": 1})
    assert more.to_dict()["scouting"]["fallback"] == 1 and more.key() != PROTOCOL.key()
    assert Protocol.from_dict(more.to_dict()) == more
