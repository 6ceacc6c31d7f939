"""A store (`lagbench run --store`): it keeps what it states and git ignores the rest; a fresh clone of the
committed store resumes training nothing, with the same verdicts, and gives the same report, a study's
section included; a unit made under another protocol or registration is redone (and only a store's run
redoes it for a registration); on Ray, as locally, each unit is trimmed as it finishes."""
import datetime as dt
import importlib.util
import json
import shutil
import subprocess

import pandas as pd
import pytest

from lagbench.files import results as R
from lagbench.replication.run import store as S
from lagbench.replication.run.runner import run

KW = dict(profile="smoke", claims=["dp_loss"], frameworks=("jax",), models=["baseline"], progress=False)
UNIT = "units/dp_loss/jax/baseline/seed1000"

pytestmark = pytest.mark.skipif(shutil.which("git") is None, reason="needs git")


def _git(cwd, *args) -> str:
    return subprocess.run(["git", "-c", "user.name=t", "-c", "user.email=t@t", *args], cwd=cwd, check=True,
                          capture_output=True, text=True).stdout


def _committed(repo, sub="runs/full") -> set:
    """What `git add` takes of the store at repo/sub: the files git keeps, relative to the store."""
    _git(repo, "add", "-A")
    return {line.removeprefix(f"{sub}/") for line in _git(repo, "ls-files", sub).splitlines()}


def _units_run(out) -> int:
    return json.loads((out / "run.json").read_text())["units_run"]


@pytest.fixture(scope="module")
def stored(tmp_path_factory):
    """A git repository holding a store of one smoke unit at runs/full, and the run's summary."""
    repo = tmp_path_factory.mktemp("repo")
    _git(repo, "init", "-q")
    out = repo / "runs" / "full"
    summary = run(out=out, store=True, **KW)
    return repo, out, summary


def test_a_store_keeps_what_it_states_and_git_takes_nothing_else(stored, tmp_path):
    repo = tmp_path / "repo"
    shutil.copytree(stored[0], repo)
    out = repo / "runs" / "full"
    d = R.load_result(out / UNIT)   # it verifies without its checkpoint
    assert not (out / UNIT / "checkpoint.npz").exists() and "checkpoint.npz" not in d["files"]
    assert set(d["store"]["removed"]) == {"checkpoint.npz"}
    assert {"result.json", "train_log.csv"} <= {p.name for p in (out / UNIT).iterdir()}
    assert list(out.glob("trained/jax/*/checkpoint.npz")), "the training cache stays, for this machine's resume"
    # files a store does without, put back by hand: the .gitignore keeps git from taking them all the same
    (out / UNIT / "checkpoint.npz").write_bytes(b"x")
    kept = out / "units/delan_arm/torch/delan/seed1000/checkpoint.npz"   # claim 12's study reads claim 9's
    kept.parent.mkdir(parents=True)
    kept.write_bytes(b"x")
    (out / "units/dp_loss/jax/baseline/superseded-1-seed1000").mkdir()
    (out / "units/dp_loss/jax/baseline/superseded-1-seed1000/result.json").write_text("{}")
    (out / "estimate_probes.json").write_text("{}")
    # a study's tables the report reads, beside what the study writes for itself alone
    read = ["robustness/scenes.csv", "robustness/study.json", "bench/inference.csv", "train_target/train_target.csv",
            "predict/double_pendulum/mine/result.json"]
    own = ["robustness/summary.md", "robustness/data/nominal-seed0.npz", "robustness/fits/nominal/seed0/a.npz",
           "robustness/.lagbench.lock", "control_four_joint_arm/data/train.npz", "bench/stages/inference.json",
           "train_target/quick.npz", "online/summary.csv", f"{UNIT}/.train_log.csv.x.tmp", "summary/.units.csv.x.tmp"]
    for rel in read + own:
        (out / rel).parent.mkdir(parents=True, exist_ok=True)
        (out / rel).write_text("x")
    committed = _committed(repo)
    assert committed == {p.as_posix() for p in S.kept_files(out)}
    assert {".gitignore", "run.json", "claims.json", f"{UNIT}/result.json", "summary/verdicts.json",
            "units/delan_arm/torch/delan/seed1000/checkpoint.npz", *read} <= committed
    assert not any(p.startswith(("trained/", "estimate_probes", ".lagbench")) or "superseded-" in p
                   or p == f"{UNIT}/checkpoint.npz" or p in own for p in committed), committed
    assert S.size(out) == sum((out / p).stat().st_size for p in committed)


def test_a_fresh_clone_of_the_store_trains_nothing_and_gives_the_same_verdicts(stored, tmp_path, capsys):
    repo, _, summary = stored
    _git(repo, "add", "-A")
    _git(repo, "commit", "-q", "-m", "store")
    clone = tmp_path / "clone"
    _git(tmp_path, "clone", "-q", str(repo), str(clone))
    out = clone / "runs" / "full"
    assert not (out / "trained").exists()
    again = run(out=out, store=True, **KW)
    assert _units_run(out) == 0
    verdicts = {c["id"]: (c["verdict"], c["reason"]) for c in summary["claims"]}
    assert {c["id"]: (c["verdict"], c["reason"]) for c in again["claims"]} == verdicts
    assert "MB of its 150 MB budget" in capsys.readouterr().out


def test_a_unit_of_another_protocol_or_registration_is_redone(stored, tmp_path, monkeypatch):
    from lagbench.replication.claims import get

    out = tmp_path / "store"
    shutil.copytree(stored[1], out)
    d = R.load_result(out / UNIT)
    assert d["protocol_hash"] == S.registration_hash(get("dp_loss"), "smoke")
    # another registration (a rule or bar changed), the protocol the same: a store redoes it, a plain run keeps it
    R.write_json(out / UNIT / "result.json", {**d, "protocol_hash": "0" * 16}, checksum=True)
    run(out=out, **KW)
    assert _units_run(out) == 0
    run(out=out, store=True, **KW)
    assert _units_run(out) == 1 and R.load_result(out / UNIT)["protocol_hash"] == d["protocol_hash"]
    (old,) = out.glob("units/dp_loss/jax/baseline/superseded-*-seed1000")
    assert R.load_result(old)["protocol_hash"] == "0" * 16   # set aside, not mixed in
    claim = get("dp_loss")
    monkeypatch.setitem(claim.protocols, "smoke", claim.protocols["smoke"].replace(steps=7))
    run(out=out, store=True, **KW)
    new = R.load_result(out / UNIT)
    assert _units_run(out) == 1 and new["protocol"]["steps"] == 7 and "checkpoint.npz" not in new["files"]
    assert new["protocol_hash"] == S.registration_hash(claim, "smoke") != d["protocol_hash"]


def test_the_store_keeps_every_study_folder_the_report_reads():
    from lagbench.reports import sections_control, sections_online, sections_verify

    read = {s.folder for s in sections_control.STUDIES} | {sections_online.FOLDER}
    assert read <= set(S.STUDIES), read - set(S.STUDIES)
    assert sections_verify.SOURCE.split("/")[0] in S.RECORDS


def _report(results, out_dir) -> str:
    """The report's Markdown of a results folder, its folder's path written as RESULTS."""
    from lagbench.reports.build import titled
    from lagbench.reports.markdown import render_markdown

    title, body, appendix = titled(results, out_dir, dt.datetime(2000, 1, 1, tzinfo=dt.UTC))
    return render_markdown(title, body + appendix).replace(results.as_posix(), "RESULTS")


def test_a_clone_of_a_store_with_a_study_gives_the_report_of_the_folder_it_was_made_from(stored, tmp_path,
                                                                                          monkeypatch):
    from lagbench.cli import main
    from lagbench.replication.studies import online as O
    from lagbench.reports.load import load_results

    repo = tmp_path / "repo"
    shutil.copytree(stored[0], repo)
    out = repo / "runs" / "full"
    monkeypatch.setattr(O, "one_thread", lambda: {"test": "threads left as they are"})
    # the cheapest study the report shows: the four-joint arm learning online, for a tenth of a second
    assert main(["online", "--system", "four_joint_arm", "--out", str(out), "--seconds", "0.1", "--window", "0.05",
                 "--models", "ff", "--frameworks", "jax", "--unseen-refs", "0", "--quiet"]) == 0
    study = out / "online_four_joint_arm"
    assert {"summary.csv", "setup.json", "curves.csv"} <= {p.name for p in study.iterdir()}
    _git(repo, "add", "-A")
    _git(repo, "commit", "-q", "-m", "store and study")
    clone = tmp_path / "clone"
    _git(tmp_path, "clone", "-q", str(repo), str(clone))
    again = clone / "runs" / "full"
    assert {p.name for p in (again / "online_four_joint_arm").iterdir()} == {"summary.csv", "setup.json"}
    assert not (again / "trained").exists()
    # the loader and the study's section read the same rows there, and the whole report is the same
    mine, theirs = load_results(out), load_results(again)
    assert [(u.rel, u.status, u.result) for u in theirs.units] == [(u.rel, u.status, u.result) for u in mine.units]
    assert theirs.verdicts == mine.verdicts and theirs.problems == mine.problems
    pd.testing.assert_frame_equal(pd.read_csv(again / "online_four_joint_arm/summary.csv"),
                                  pd.read_csv(study / "summary.csv"))
    report = _report(again, tmp_path / "report_clone")
    assert "Learning online while tracking the four-joint arm" in report
    assert report == _report(out, tmp_path / "report_folder")


@pytest.mark.slow   # a Ray instance's start-up (tox -e slow)
@pytest.mark.skipif(importlib.util.find_spec("ray") is None, reason="Ray is an optional extra")
def test_on_ray_each_unit_is_trimmed_as_it_finishes(tmp_path, monkeypatch):
    """The end of the run's trimming left out (as when the driver stops): the unit is trimmed all the same."""
    monkeypatch.setenv("LAGBENCH_WORKER_DIR", str(tmp_path / "worker"))
    monkeypatch.setattr(S, "prune", lambda out: 0)
    out = tmp_path / "store"
    summary = run(out=out, store=True, executor="ray", **KW)
    assert summary["errors"] == []
    d = R.load_result(out / UNIT)
    assert set(d["store"]["removed"]) == {"checkpoint.npz"} and not (out / UNIT / "checkpoint.npz").exists()
