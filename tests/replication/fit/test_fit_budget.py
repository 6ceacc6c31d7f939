"""`lagbench fit`'s budget follows the data (`kind_defaults.SMALL`): a system with fewer coordinates than the
kind's claim trains without restarts, for the claim's steps, and stops early when its held-out error stops
improving (`--patience`); the double pendulum keeps the claim's and the fit study's budget, and on a noisy
recording (`kind_defaults.NOISY_RECORDINGS`) the claim's steps without restart fallbacks. One progress bar
counts the restarts' steps and the main training's (`replication.fit.progress`)."""
import json

import pytest

from lagbench.cli import main
from lagbench.replication.fit import kind_defaults, progress
from lagbench.replication.fit.resolve import resolved
from lagbench.replication.fit.task import fit
from lagbench.replication.training.scouting import budget_samples


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("data")
    out = {}
    for system in ("pendulum", "double_pendulum"):
        out[system] = folder / f"{system}.csv"
        assert main(["simulate", "--system", system, "--trajectories", "10", "--duration", "2", "--rate", "100",
                     "--noise", "0", "--out", str(out[system])]) == 0
    for noise in ("0.001", "0.01", "0.01 velocities"):   # quiet and noisy recordings of the double pendulum
        out[noise] = folder / f"double_pendulum_{noise.replace(' ', '_')}.csv"
        assert main(["simulate", "--system", "double_pendulum", "--trajectories", "10", "--duration", "2", "--rate",
                     "100", "--noise", noise.split()[0], "--out", str(out[noise])]
                    + (["--velocities"] if "velocities" in noise else [])) == 0
    return out


def test_a_pendulum_gets_the_sized_budget_and_the_double_pendulum_the_studys(files):
    claim = kind_defaults.defaults("lnn", "acceleration")
    small, dp = resolved(files["pendulum"], {"model": "lnn"}), resolved(files["double_pendulum"], {"model": "lnn"})
    assert (small.dof, dp.dof) == (1, 2) and kind_defaults.claim_dof("lnn", "acceleration") == 2
    assert (small.options.steps, small.options.restarts, small.options.patience) == (claim["steps"], None,
                                                                                   kind_defaults.SMALL["patience"])
    factor = kind_defaults.ON_RECORDINGS[("lnn", "acceleration")]
    assert (dp.options.steps, dp.options.restarts, dp.options.patience) == (factor * claim["steps"], claim["restarts"], 0)
    assert kind_defaults.SMALL["patience"] > 0 and claim["restarts"]
    same = ("hidden", "lr", "batch", "schedule", "loss", "guard_clip", "input_scale")
    assert {k: getattr(small.options, k) for k in same} == {k: getattr(dp.options, k) for k in same}
    # given options win; the HNN's claim is the pendulum's, so a pendulum is not smaller than it
    given = resolved(files["pendulum"], {"model": "lnn", "patience": 0, "restarts": 4, "steps": 50}).options
    assert (given.patience, given.restarts, given.steps) == (0, 4, 50)
    assert not kind_defaults.small("hnn", "hamiltonian", 1) and kind_defaults.small("delan", "inverse_dynamics", 1)
    assert "no restarts, an early stop" in kind_defaults.source("lnn", "acceleration", True, 1)
    assert "early stop" not in kind_defaults.source("lnn", "acceleration", True, 2)
    # the steps' factor is named only where the steps are the default's
    assert "x its steps on a trajectory file" in kind_defaults.source("lnn", "acceleration", True, 2)
    assert "x its steps" not in kind_defaults.source("lnn", "acceleration", True, 2, given={"steps"})


def test_a_noisy_recording_trains_the_claims_steps_without_fallbacks(files):
    """The switch reads the position noise `--window auto` estimates on q (within 5 % of the simulated noise at
    100 Hz): a recording at or above it trains the claim's steps and restarts without a fallback, one below it
    and a clean one the study's longer budget; a given --steps or --restart-fallback wins, and a file that gives
    its velocities (nothing estimated from q alone) keeps the longer budget."""
    claim, switch = kind_defaults.defaults("lnn", "acceleration"), kind_defaults.NOISY_RECORDINGS[("lnn", "acceleration")]
    factor = kind_defaults.ON_RECORDINGS[("lnn", "acceleration")]
    got = {k: resolved(files[k], {"model": "lnn"}) for k in ("double_pendulum", "0.001", "0.01")}
    assert got["0.001"].noise == pytest.approx(0.001, rel=0.05) and got["0.01"].noise == pytest.approx(0.01, rel=0.05)
    assert got["double_pendulum"].noise < 1e-4 < 0.001 < switch <= 0.01
    for k in ("double_pendulum", "0.001"):
        o = got[k].options
        assert (o.steps, o.restarts, o.restart_fallback) == (factor * claim["steps"], claim["restarts"],
                                                              claim["restart_fallback"])
    o = got["0.01"].options
    assert (o.steps, o.restarts, o.restart_fallback) == (claim["steps"], claim["restarts"], 0) and claim["restart_fallback"]
    assert o.restart_steps == max(2, round(claim["steps"] * claim["restart_fraction"]))
    given = resolved(files["0.01"], {"model": "lnn", "steps": 500, "restart_fallback": 1}).options
    assert (given.steps, given.restart_fallback) == (500, 1)
    with_velocities = resolved(files["0.01 velocities"], {"model": "lnn"})
    assert with_velocities.noise is None and with_velocities.options.steps == factor * claim["steps"]
    # the baseline's budget does not follow the noise; a sized-down system's neither
    assert resolved(files["0.01"], {"model": "baseline"}).noise is None
    assert not kind_defaults.noisy("baseline", "acceleration", 1.0) and kind_defaults.noisy("lnn", "acceleration", switch)
    assert kind_defaults.defaults("lnn", "acceleration", True, 1, noise=1.0) == kind_defaults.defaults("lnn", "acceleration", True, 1)
    line = kind_defaults.source("lnn", "acceleration", True, 2, noise=got["0.01"].noise)
    assert "its steps and restarts without a fallback on a noisy trajectory file" in line and "x its steps" not in line
    assert "noisy" not in kind_defaults.source("lnn", "acceleration", True, 2, noise=got["0.001"].noise)


def test_the_switch_sits_between_the_studys_recordings(tmp_path):
    """The switch is the geometric mean of the position noise estimated on the registered study's training
    recordings at 0.001 rad (where 3 x rolled out better) and 0.003 rad (where 1 x did):
    docs/lab/recording_defaults.md, item 5."""
    from lagbench.files import user_data
    from lagbench.replication.fit import trajectories

    noise = []
    for level in ("0.001", "0.003"):
        path = tmp_path / f"{level}.csv"
        assert main(["simulate", "--system", "double_pendulum", "--set", "friction=0.2", "--rate", "100", "--dropped",
                     "0.02", "--trajectories", "400", "--duration", "1", "--seed", "30", "--noise", level,
                     "--out", str(path)]) == 0
        noise.append(trajectories.position_noise(user_data.read(str(path))[1], str(path)))
    assert noise[0] == pytest.approx(0.001, rel=0.02) and noise[1] == pytest.approx(0.003, rel=0.02)
    assert kind_defaults.NOISY_RECORDINGS[("lnn", "acceleration")] == pytest.approx((noise[0] * noise[1]) ** 0.5, rel=5e-3)


def test_a_restart_fallback_or_keep_given_alone_is_checked_against_the_kinds_restarts(files):
    claim = kind_defaults.defaults("lnn", "acceleration")
    assert resolved(files["double_pendulum"], {"model": "lnn", "restart_fallback": 1}).options.restart_fallback == 1
    assert resolved(files["double_pendulum"], {"model": "lnn", "restart_keep": 2}).options.restart_keep == 2
    with pytest.raises(ValueError, match=f"--restart-fallback: {claim['restarts']}.*{claim['restart_keep']} do"):
        resolved(files["double_pendulum"], {"model": "lnn", "restart_fallback": claim["restarts"]})


def test_a_fit_stops_when_its_heldout_error_stops_improving(files, tmp_path):
    """A rate too small to move the model: the held-out error cannot improve, so the fit stops `patience`
    evaluations after its first and anneals over the steps its patience spans; the record says when, and
    counts the samples it trained."""
    d = fit(files["pendulum"], model="baseline", out=tmp_path / "a", steps=200, hidden=(8,), batch=16, lr=1e-9,
            schedule="constant", patience=3)
    every = 200 // kind_defaults.HELDOUT_CHECKS
    assert d["protocol"]["early_stop"] == {"every": every, "patience": 3, "min_improvement": kind_defaults.MIN_IMPROVEMENT,
                                           "anneal": 3 * every}
    assert d["early_stop"]["stopped_at"] == 3 * every and d["train_steps"] == 3 * every + 1 + 3 * every
    assert d["train_samples"] == d["train_steps"] * 16
    stored = json.loads((tmp_path / "a" / "units" / "fit" / "jax" / "baseline" / "seed0" / "result.json").read_text())
    assert stored["early_stop"] == d["early_stop"]
    moving = fit(files["pendulum"], model="baseline", out=tmp_path / "b", steps=200, hidden=(8,), batch=16, patience=0)
    assert "early_stop" not in moving["protocol"] and "early_stop" not in moving and moving["train_steps"] == 200


def test_patience_without_heldout_rows_is_refused(files, tmp_path, capsys):
    assert main(["fit", "--data", str(files["pendulum"]), "--model", "lnn", "--holdout", "none", "--patience", "5",
                 "--out", str(tmp_path / "x")]) == 2
    assert "--patience 5: the early stop reads held-out rows" in capsys.readouterr().err
    # at the defaults (an early stop for a pendulum) a split without held-out rows trains to its steps
    d = fit(files["pendulum"], model="baseline", out=tmp_path / "n", split="none", steps=20, hidden=(8,), batch=16)
    assert "early_stop" not in d["protocol"] and d["train_steps"] == 20


def test_the_bar_counts_the_restarts_steps_and_the_main_steps_in_one_total(files, tmp_path):
    protocols, rows = [], []
    fit(files["double_pendulum"], model="lnn", out=tmp_path / "r", steps=8, hidden=(8,), batch=16, restarts=4,
        restart_steps=6, restart_keep=2, restart_batch=8, restart_fallback=0, on_train=protocols.append,
        on_log=rows.append)
    (p,) = protocols
    assert progress.total_steps(p) == 6 + 8   # the restarts train side by side: 6 steps, then 8 main steps
    done = [progress.position(p, r) for r in rows]
    assert done == sorted(done) and done[-1] == progress.total_steps(p)
    assert [progress.position(p, r) for r in rows if "restart_step" in r][-1] == 6
    # the time left at one second a sample is the samples the whole training has: restarts (4, then 2 after the
    # cut, at their batch) and the main training's
    assert progress.seconds_left(p, 0, 1.0) == budget_samples(p) == (4 * 3 + 2 * 3) * 8 + 8 * 16
    assert progress.seconds_left(p, 6, 1.0) == 8 * 16 and progress.seconds_left(p, 14, 1.0) == 0
    # a fallback (the next restart's main training) goes on past the first one's end, 8 steps each
    assert [progress.fallbacks(p, at) for at in (6, 14, 15, 22, 23)] == [0, 0, 1, 1, 2]
    bar = progress.TrainingBar("t")
    bar.start(p.replace(**{"scouting.fallback": 1}))
    for r in rows:
        bar.row(r)
    assert bar.bar.total == bar.bar.n == progress.total_steps(p)   # open: a fallback may follow
    bar.row({**rows[-1], "step": rows[-1]["step"] + 1})             # the fallback's first step
    assert bar.bar.total == progress.total_steps(p) + 8 and bar.bar.n == progress.total_steps(p) + 1
    bar.close()


def test_the_bar_ends_at_its_total_or_says_where_the_training_ended(files, tmp_path, capsys):
    assert main(["fit", "--data", str(files["pendulum"]), "--model", "baseline", "--steps", "200", "--hidden", "8",
                 "--batch", "16", "--lr", "1e-9", "--schedule", "constant", "--patience", "3",
                 "--out", str(tmp_path / "c")]) == 0
    captured = capsys.readouterr()
    # evaluations at steps 0, 2, 4, 6: it stops after the 7th step and anneals over 3 x 2 more
    assert "ended at step 13 of 200" in captured.err
    assert "early stop at step 7 of 200" in captured.err and "annealed over 6 more steps, 13 in all" in captured.err
    assert captured.out.startswith("done: held-out L1 ")   # the result line alone on stdout (untrained: "done")
