"""A store (`lagbench run --store`): it keeps what it states and git ignores the rest; a fresh clone of the
committed store resumes training nothing, with the same verdicts; a unit made under another protocol or
registration is redone (and only a store's run redoes it for a registration)."""
import json
import shutil
import subprocess

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
    committed = _committed(repo)
    assert committed == {p.as_posix() for p in S.kept_files(out)}
    assert {".gitignore", "run.json", "claims.json", f"{UNIT}/result.json", "summary/verdicts.json",
            "units/delan_arm/torch/delan/seed1000/checkpoint.npz"} <= committed
    assert not any(p.startswith(("trained/", "estimate_probes", ".lagbench")) or "superseded-" in p
                   or p == f"{UNIT}/checkpoint.npz" for p in committed), committed
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
