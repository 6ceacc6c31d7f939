"""One meaning per option name across the commands (`lagbench.options`): --frameworks, --seeds (the seeds) and
--n-seeds (how many), --out (what a command writes); the old spellings still read with one notice; every
command described, its defaults written one way; errors that name the unknown system or the missing column."""
import argparse
import re

import numpy as np
import pandas as pd
import pytest

from lagbench import options
from lagbench.cli import build_parser, main

NOTE = "lagbench: note: {old} is now {new}; the old spelling is read until the next release"


def _commands():
    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return parser, sub.choices


COMMANDS = sorted(_commands()[1])


def _visible(parser) -> dict:
    return {s: a for a in parser._actions if a.help != argparse.SUPPRESS for s in a.option_strings}


@pytest.mark.parametrize("name", ["", *COMMANDS])
def test_every_command_is_described_and_writes_its_defaults_one_way(name, capsys):
    parser, commands = _commands()
    with pytest.raises(SystemExit) as done:
        parser.parse_args([*([name] if name else []), "--help"])
    assert done.value.code == 0
    text = " ".join(capsys.readouterr().out.split())
    command = commands[name] if name else parser
    assert command.description and "".join(command.description.split())[:60] in "".join(text.split())
    assert "SUPPRESS" not in text
    odd = [text[max(0, m.start() - 40):m.end() + 20] for m in re.finditer("default", text)
           if text[m.start() - 1:m.end() + 2] != "(default: "]
    assert odd == []
    for action in command._actions:   # each option that takes a value, and is not required, names its default
        if action.option_strings and action.nargs != 0 and action.help != argparse.SUPPRESS and not action.required:
            rendered = " ".join(action.help.replace("%(default)s", str(action.default)).split())
            assert "(default: " in rendered or rendered.startswith("required"), (name, action.option_strings)


def test_help_texts_the_issue_named():
    _, commands = _commands()
    fitted, device = (next(a for a in commands["evaluate"]._actions if flag in a.option_strings)
                      for flag in ("--fitted", "--device"))
    assert fitted.help.startswith("required") and "(default" not in fitted.help
    assert "predict and roll out" in device.help and "train" not in device.help
    assert "issue" not in commands["train-target"].format_help()
    assert "3e7" in commands["train-target"].format_help()   # the target named for what it is


def test_each_name_means_one_thing_in_every_command():
    _, commands = _commands()
    for name, command in commands.items():
        shown = _visible(command)
        assert "--framework" not in shown, name
        assert "--results" not in shown or name in ("report", "table", "verify"), name   # readers: their input folder
        if "--seeds" in shown:
            assert shown["--seeds"].nargs == "+", name   # the seeds themselves
        if "--frameworks" in shown:
            assert shown["--frameworks"].dest in ("framework", "frameworks"), name
    for name in ("run", "tune"):
        assert "--n-seeds" in _visible(commands[name])
    writes = {name for name, c in commands.items() if "--out" in _visible(c)}
    assert writes == set(COMMANDS) - {"list", "table", "verify"}   # table, verify: into the results folder read
    required = {name for name in writes if _visible(commands[name])["--out"].required}
    assert required == {"simulate"}   # a file, never assumed; every folder has a default


def test_online_defaults_to_the_frameworks_of_runs_quick_profile():
    from lagbench.replication.claims.base import run_frameworks

    args = build_parser().parse_args(["online"])
    assert options.frameworks(args.frameworks) == tuple(run_frameworks("quick", None))


@pytest.mark.parametrize("argv, dest, value, old, new", [
    (["fit", "--data", "d.csv", "--model", "lnn", "--framework", "torch"], "framework", "torch", "--framework",
     "--frameworks"),
    (["evaluate", "--fitted", "f", "--data", "d.csv", "--framework", "torch"], "framework", "torch", "--framework",
     "--frameworks"),
    (["control", "--system", "four_joint_arm", "--framework", "torch"], "framework", "torch", "--framework",
     "--frameworks"),
    (["robustness", "--framework", "torch"], "framework", "torch", "--framework", "--frameworks"),
    (["control", "--results", "elsewhere"], "out", "elsewhere", "--results", "--out"),
    (["train-target", "--heldout", "64"], "heldout_states", 64, "--heldout", "--heldout-states"),
    (["run", "--seeds", "3"], "n_seeds", 3, "--seeds N (a count)", "--n-seeds N"),
    (["tune", "--claim", "dp_loss", "--seeds", "2"], "n_seeds", 2, "--seeds N (a count)", "--n-seeds N"),
])
def test_an_old_spelling_is_read_with_one_notice_and_the_new_one_without(argv, dest, value, old, new, capsys):
    args = build_parser().parse_args(argv)
    assert getattr(args, dest) == value
    err = capsys.readouterr().err
    assert err.startswith(NOTE.format(old=old, new=new)) and err.count("\n") == 1
    if old.startswith("--seeds"):
        assert args.seeds is None
        given = [a if a != "--seeds" else "--n-seeds" for a in argv]
    else:
        given = [new if a == old else a for a in argv]
    assert getattr(build_parser().parse_args(given), dest) == value and capsys.readouterr().err == ""


def test_an_old_spelling_given_twice_is_noticed_once_and_two_spellings_are_refused(capsys):
    args = build_parser().parse_args(["fit", "--data", "d", "--model", "lnn", "--framework", "jax", "--framework",
                                      "torch"])
    assert args.framework == "torch" and capsys.readouterr().err.count("note:") == 1
    for argv in (["fit", "--data", "d", "--model", "lnn", "--frameworks", "jax", "--framework", "torch"],
                 ["fit", "--data", "d", "--model", "lnn", "--framework", "jax", "--frameworks", "torch"],
                 ["run", "--n-seeds", "2", "--seeds", "3"], ["control", "--results", "a", "--out", "b"]):
        with pytest.raises(SystemExit) as done:
            build_parser().parse_args(argv)
        assert done.value.code == 2 and "are one option; give it once" in capsys.readouterr().err


def test_seeds_read_alike_and_a_run_trains_the_seeds_it_is_given():
    from lagbench.replication.run.runner import plan

    assert options.seeds(["3,1", "2", "1"]) == (3, 1, 2)
    args = build_parser().parse_args(["run", "--seeds", "1003", "1001,"])
    assert options.seeds_or_count(args) == (1003, 1001)
    one = build_parser().parse_args(["run", "--seeds", "1000,"])   # one seed, told from a count by its comma
    assert options.seeds_or_count(one) == (1000,)
    units = plan("smoke", ["dp_loss"], ["jax"], seeds=(1003, 1001), split="test")
    assert sorted({u.seed for u in units}) == [1001, 1003]
    assert sorted({u.seed for u in plan("smoke", ["dp_loss"], ["jax"], seeds=2, split="test")}) == [1000, 1001]
    with pytest.raises(ValueError, match="--seeds: 5: not seeds of the test split"):
        plan("smoke", ["dp_loss"], ["jax"], seeds=(5,), split="test")


def test_tune_searches_on_the_development_seeds_it_is_given(tmp_path, monkeypatch):
    from lagbench.replication.tuning import tune as T

    told = []
    monkeypatch.setattr(T._Runner, "tell", lambda self, stage, plan: told.append(plan))
    assert T.tune("dp_loss", out=tmp_path / "t", seeds=[4, 2], dry_run=True) is None
    assert {tuple(seeds) for _, _, _, seeds in told[0]} == {(4, 2)}
    with pytest.raises(ValueError, match="--seeds: 1000: not development seeds"):
        T.tune("dp_loss", out=tmp_path / "u", seeds=[1000], dry_run=True)
    assert not (tmp_path / "u").exists()


@pytest.mark.parametrize("argv", [
    ["fit", "--data", "d.csv", "--model", "lnn"],
    ["evaluate", "--fitted", "f", "--data", "d.csv"],
    ["control", "--system", "four_joint_arm"],
    ["robustness"],
])
@pytest.mark.parametrize("given, says", [("jax,torch", "runs in one framework"), ("tf", "one of jax, torch")])
def test_a_command_of_one_framework_takes_exactly_one(argv, given, says, tmp_path, capsys):
    out = tmp_path / "out"
    assert main([*argv, "--frameworks", given, "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err == f"lagbench: error: --frameworks {given}: `lagbench {argv[0]}` runs in one framework; give one of " \
                  "jax, torch\n" and says in err
    assert not out.exists()


def test_control_reads_claim_9_from_trained_from_and_writes_into_out(tmp_path, capsys):
    trained, out = tmp_path / "trained", tmp_path / "out"
    trained.mkdir()
    assert main(["control", "--trained-from", str(trained), "--out", str(out), "--references", "1",
                 "--duration", "0.2", "--quiet"]) == 0
    assert (out / "control" / "tracking.csv").exists() and list(trained.iterdir()) == []
    capsys.readouterr()
    for argv, words in ((["--trained-from", str(tmp_path / "none")], "--trained-from"),
                        (["--system", "four_joint_arm", "--trained-from", str(trained)], "--trained-from: the "
                                                                                         "two_link_arm's option")):
        assert main(["control", "--out", str(tmp_path / "o"), *argv, "--quiet"]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and words in err
    assert not (tmp_path / "o").exists()


def test_an_unknown_system_is_named_unknown_with_the_known_ones(tmp_path, monkeypatch, capsys):
    from lagbench import systems
    from lagbench.replication.predictor.score import setup

    with pytest.raises(ValueError, match=r"--system double_pendulm: unknown system \(did you mean double_pendulum\?\)"):
        setup("double_pendulm")
    (tmp_path / "mine.py").write_text("import numpy as np\n\ndef zero(q, qdot):\n    return np.zeros_like(q)\n")
    monkeypatch.chdir(tmp_path)
    assert main(["evaluate", "--predict", "mine:zero", "--system", "double_pendulm", "--out", "o"]) == 2
    err = capsys.readouterr().err
    assert "unknown system" in err and all(n in err for n in systems.names()) and "no claim" not in err
    with pytest.raises(ValueError, match="--system wave: no claim scores"):   # known, but scored by no claim
        setup("wave")


def _positions(path, t, traj=None):
    cols = {**({"traj": traj} if traj is not None else {}), "t": t, "q0": np.sin(t)}
    pd.DataFrame({k: v for k, v in cols.items() if v is not None}).to_csv(path, index=False)
    return path


def test_a_csv_without_t_is_told_its_t_column_is_missing(tmp_path):
    from lagbench.files import user_data

    path = tmp_path / "no_t.csv"
    pd.DataFrame({"q0": np.sin(np.arange(40) * 0.02)}).to_csv(path, index=False)
    with pytest.raises(ValueError, match="no column t: positions q without qdot and qddot are a trajectory file"):
        user_data.read(str(path))
    npz = tmp_path / "no_t.npz"
    np.savez(npz, q=np.zeros((40, 1)), qdot=np.zeros((40, 1)))
    with pytest.raises(ValueError, match="no array t: positions q without qddot"):
        user_data.read(str(npz))


@pytest.mark.parametrize("how", ["go back", "repeat"])
def test_times_that_repeat_or_go_back_without_traj_name_the_traj_column(tmp_path, how, capsys):
    from lagbench.files import user_data
    from lagbench.replication.fit import trajectories

    one = np.arange(40) * 0.02
    t = np.concatenate([one, one]) if how == "go back" else np.repeat(one, 2)
    path = str(_positions(tmp_path / "two.csv", t))
    with pytest.raises(ValueError, match=f"its times {how} .* no traj column, .* several trajectories need a traj "
                                         f"column"):
        trajectories.with_derivatives(user_data.read(path)[1], path)
    assert main(["fit", "--data", path, "--model", "baseline", "--out", str(tmp_path / "o")]) == 2
    assert capsys.readouterr().err.splitlines()[-1].startswith(f"lagbench: error: {path}: its times {how}")
    traj = np.repeat([0, 1], 40) if how == "go back" else np.tile([0, 1], 40)
    named = str(_positions(tmp_path / "named.csv", t, traj))   # the same times, each row's trajectory named
    assert set(trajectories.with_derivatives(user_data.read(named)[1], named)["traj"]) == {0.0, 1.0}
