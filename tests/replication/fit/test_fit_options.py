"""`lagbench fit`'s options are one record (`replication.fit.options`): the command line's defaults are the
function's, every option is checked by its own rule, and an unknown keyword is refused."""
import pytest

from lagbench.cli import build_parser
from lagbench.replication.fit import kind_defaults
from lagbench.replication.fit import options as fit_options
from lagbench.replication.fit.task import fit


def test_the_command_lines_defaults_are_the_functions():
    args = build_parser().parse_args(["fit", "--data", "d.csv", "--model", "lnn"])
    given = fit_options.from_args(args)
    by_kind = {o.name for o in fit_options.OPTIONS if o.default is fit_options.BY_KIND}
    assert set(given) == set(fit_options.BY_NAME) - by_kind   # the kind's defaults come in after the data is read
    assert vars(fit_options.resolve(given)) == vars(fit_options.resolve({"model": "lnn"}))


def test_every_flag_is_in_the_help_with_its_default(capsys):
    with pytest.raises(SystemExit):
        build_parser().parse_args(["fit", "--help"])
    out = " ".join(capsys.readouterr().out.split())
    for o in fit_options.OPTIONS:
        assert o.cli in out
        if o.default is fit_options.BY_KIND:
            assert " ".join(o.help.split()) in out and fit_options.KIND.strip() in o.help, o.name
        elif not o.switch and o.default is not None and not o.required:
            shown = o.text if o.parse is not None else o.default
            assert f"(default: {shown})" in out, o.name


@pytest.mark.parametrize("name, value", [("steps", 0), ("lr", float("inf")), ("loss", "huber"), ("hidden", (8, 0)),
                                         ("horizon", -1.0), ("lr_min_ratio", 2.0), ("input_scale", (1.0, -1.0))])
def test_each_option_is_checked_by_its_own_rule(name, value):
    flag = fit_options.BY_NAME[name].cli
    with pytest.raises(ValueError, match=f"^{flag}: "):
        fit_options.check({name: value})


def test_an_unknown_keyword_is_refused(tmp_path):
    with pytest.raises(TypeError, match="unknown options stepz"):
        fit(tmp_path / "d.csv", out=tmp_path / "o", stepz=3)


@pytest.mark.parametrize("kind, task", sorted(kind_defaults.SOURCES))
def test_a_fit_at_its_defaults_trains_as_the_claim_that_tuned_its_kind(tmp_path, kind, task):
    """The protocol `fit` builds from the kind's defaults is the claim's quick protocol with its adopted tuning
    in every training part (schedule, restarts and their halving, guard, batch, steps, loss, L2, width)."""
    from lagbench.replication.claims.base import per_profile
    from lagbench.replication.fit import task as fit_task
    from lagbench.replication.training.protocol import Guard, Scouting
    from lagbench.replication.training.schedules import Constant, OneCycle

    claim, entry, p = kind_defaults._entry(kind, task)
    assert p == entry.protocol(per_profile(claim.protocols, "quick"), "quick")
    o = kind_defaults.fill(fit_options.resolve({"model": kind}), task)
    schedule = OneCycle(lr=o.lr, start=o.lr_start, min_ratio=o.lr_min_ratio) if o.schedule == "onecycle" else Constant(o.lr)
    assert (schedule, o.steps, o.batch, o.loss, o.weight_decay) == (p.schedule, p.steps, p.batch, p.loss, p.l2)
    assert o.hidden == entry.widths("quick") and o.activation == entry.spec_fields("quick")["activation"]
    assert (Guard(o.guard_clip, o.guard_skip) if o.guard_clip else None) == p.guard
    scouting = Scouting(o.restarts, o.restart_steps, o.restart_batch, OneCycle(lr=o.restart_lr, min_ratio=o.lr_min_ratio),
                        o.restart_keep, o.restart_fallback or 0) if o.restarts else None
    assert scouting == p.scouting
    assert (o.input_scale == "auto") == ("input_scale" in entry.spec_fields("quick"))
    assert fit_task.LOSS_NAMES[o.loss]


def test_a_given_option_beats_the_kinds_default_and_zero_turns_a_part_off():
    o = kind_defaults.fill(fit_options.resolve({"model": "lnn", "steps": 300, "lr": 0.02, "restarts": 4,
                                                "guard_clip": 0}), "acceleration")
    d = kind_defaults.defaults("lnn", "acceleration")
    assert (o.steps, o.lr, o.restarts, o.guard_clip, o.guard_skip) == (300, 0.02, 4, None, d["guard_skip"])
    assert o.restart_keep is None   # the kind keeps 4 of 16: not of 4
    assert o.restart_steps == round(300 * d["restart_fraction"]) and o.restart_lr == pytest.approx(0.02 * d["restart_lr_ratio"])
    off = kind_defaults.fill(fit_options.resolve({"model": "lnn", "restarts": 0}), "acceleration")
    assert (off.restarts, off.restart_keep) == (None, None)
    with pytest.raises(ValueError, match="^--restarts: 1 is not valid"):
        kind_defaults.fill(fit_options.resolve({"model": "lnn", "restarts": 1}), "acceleration")


def _trajectory_and_state_files(folder):
    """A two-trajectory file (traj, t, q) and a file of state samples (q, qdot, qddot) of two coordinates."""
    import numpy as np

    t = np.arange(40) * 0.01
    traj = folder / "traj.csv"
    np.savetxt(traj, np.column_stack([np.repeat([0, 1], 20), np.tile(t[:20], 2), np.sin(t), np.cos(t)]),
               delimiter=",", header="traj,t,q0,q1", comments="")
    states = folder / "states.csv"
    np.savetxt(states, np.column_stack([np.sin(t), np.cos(t), t, -t, t ** 2, 1 - t]), delimiter=",",
               header="q0,q1,qdot0,qdot1,qddot0,qddot1", comments="")
    return traj, states


def test_a_trajectory_file_gets_the_fit_studys_budget_and_a_state_file_the_claims(tmp_path):
    """`ON_RECORDINGS` multiplies the kind's steps for a trajectory file only (the restarts follow the steps);
    every other default and every other kind stays the claim's."""
    from lagbench.replication.fit.resolve import resolved

    traj, states = _trajectory_and_state_files(tmp_path)
    for kind in ("lnn", "baseline"):
        factor = kind_defaults.ON_RECORDINGS.get((kind, "acceleration"), 1)
        on_file, on_states = resolved(traj, {"model": kind})[0], resolved(states, {"model": kind})[0]
        claim = kind_defaults.defaults(kind, "acceleration")
        assert (on_states.steps, on_file.steps) == (claim["steps"], factor * claim["steps"])
        assert on_file.restart_steps == max(2, round(on_file.steps * claim["restart_fraction"]))
        same = {k: v for k, v in vars(on_file).items() if k not in ("steps", "restart_steps")}
        assert same == {k: v for k, v in vars(on_states).items() if k not in ("steps", "restart_steps")}
        assert resolved(traj, {"model": kind, "steps": 50})[0].steps == 50   # a given --steps wins
        assert (resolved(traj, {"model": kind}).recording, resolved(states, {"model": kind}).recording) == (True, False)
    assert kind_defaults.ON_RECORDINGS[("lnn", "acceleration")] > 1


def test_the_console_line_names_where_a_recordings_defaults_come_from(tmp_path, monkeypatch, capsys):
    """`lagbench fit` on a trajectory file says, before training, that the LNN's steps are the claim's times
    the trajectory-file factor; on a file of states it names the claim alone."""
    from lagbench.cli import main
    from lagbench.replication.fit import task

    def stop(*args, **kwargs):
        raise ValueError("stopped before training")

    monkeypatch.setattr(task, "fit", stop)
    traj, states = _trajectory_and_state_files(tmp_path)
    factor = kind_defaults.ON_RECORDINGS[("lnn", "acceleration")]
    lines = {}
    for name, path in (("traj", traj), ("states", states)):
        assert main(["fit", "--data", str(path), "--model", "lnn", "--out", str(tmp_path / name)]) != 0
        lines[name] = next(ln for ln in capsys.readouterr().err.splitlines() if "defaults from" in ln)
    assert f"{factor} x its steps on a trajectory file" in lines["traj"]
    assert "on a trajectory file" not in lines["states"]


def test_even_velocity_is_for_the_lnn_and_reaches_its_spec():
    with pytest.raises(ValueError, match="^--even-velocity: for --model lnn"):
        fit_options.check({"model": "hnn", "even_velocity": True})
    fit_options.check({"model": "lnn", "even_velocity": True})
    from types import SimpleNamespace

    from lagbench.replication.fit.task import _model_spec
    o = fit_options.resolve({"model": "lnn", "even_velocity": True, "input_scale": None, "periodic": ()})
    prep = SimpleNamespace(dof=2)
    assert _model_spec(o, prep, "acceleration")["even_velocity"] is True
    o.even_velocity = False
    assert "even_velocity" not in _model_spec(o, prep, "acceleration")
