"""`lagbench run` and the command line under bad options, OS errors, Ctrl-C and repairs: every problem
is one line naming the option and a non-zero exit before any work, and no record is lost (issue 25,
cases 5, 7 and 8)."""
import json

import pytest

from lagbench.cli import main
from lagbench.replication.run import runner, units

ONE = ["--profile", "smoke", "--claims", "dp_loss", "--frameworks", "jax", "--models", "baseline", "--quiet"]


@pytest.mark.parametrize("args, words", [
    (["--n-seeds", "0"], ["--n-seeds", "from 1 to 1000"]),
    (["--n-seeds", "-1"], ["--n-seeds", "from 1 to 1000"]),
    (["--seeds", "999,1000"], ["--seeds", "999", "from 1000 to 1999"]),
    (["--seeds", "a,1"], ["--seeds", "integers >= 0"]),
    (["--seeds", "1000,", "--n-seeds", "1"], ["--seeds", "--n-seeds", "not both"]),
    (["--models", "lnnn"], ["--models", "lnnn", "valid:", "baseline"]),
    (["--frameworks", "jax,jax"], ["--frameworks", "jax", "more than once"]),
    (["--claims", "dp_loss,dp_loss"], ["--claims", "more than once"]),
    (["--frameworks", "mxnet"], ["unknown framework", "jax, torch"]),
])
def test_options_that_plan_nothing_or_twice_are_refused_before_any_work(tmp_path, capsys, args, words):
    out = tmp_path / "out"
    assert main(["run", "--profile", "smoke", "--claims", "dp_loss", "--out", str(out), "--quiet", *args]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and all(w in err for w in words), err
    assert not out.exists()


@pytest.mark.parametrize("make", ["file", "under_a_file"])
def test_a_bad_out_is_one_line_before_any_work(tmp_path, capsys, make):
    (tmp_path / "f").write_text("x")
    out = tmp_path / "f" if make == "file" else tmp_path / "f" / "sub"
    assert main(["run", *ONE, "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("lagbench: error: --out"), err


def test_os_errors_are_one_line(monkeypatch, tmp_path, capsys):
    def denied(**kw):
        raise PermissionError(13, "Permission denied", str(tmp_path / "x"))

    monkeypatch.setattr(runner, "run", denied)
    assert main(["run", *ONE, "--out", str(tmp_path)]) == 2
    assert capsys.readouterr().err == f"lagbench: error: Permission denied: {tmp_path / 'x'}\n"


def test_ctrl_c_says_how_to_resume_and_is_recorded(monkeypatch, tmp_path, capsys):
    def interrupt(*a, **kw):
        raise KeyboardInterrupt

    monkeypatch.setattr(units, "run_unit", interrupt)   # what the executor calls for every unit
    assert main(["run", *ONE, "--out", str(tmp_path)]) == 130
    err = capsys.readouterr().err
    assert "interrupted; finished units are kept; run the same command again to resume" in err
    assert "Traceback" not in err
    manifest = json.loads((tmp_path / "run.json").read_text())
    assert manifest["interrupted"] and manifest["finished"] is None


def test_sigterm_is_recorded_like_ctrl_c_and_says_how_to_resume(monkeypatch, tmp_path, capsys):
    import os
    import signal
    import time

    def killed(*a, **kw):   # a real SIGTERM to this process, in the middle of a unit
        os.kill(os.getpid(), signal.SIGTERM)
        time.sleep(5)

    before = signal.getsignal(signal.SIGTERM)
    monkeypatch.setattr(units, "run_unit", killed)
    try:
        assert main(["run", *ONE, "--out", str(tmp_path)]) == 143
    finally:
        signal.signal(signal.SIGTERM, before)
    err = capsys.readouterr().err
    assert "terminated (SIGTERM); finished units are kept; run the same command again to resume" in err
    assert "Traceback" not in err
    manifest = json.loads((tmp_path / "run.json").read_text())
    assert manifest["interrupted"] and manifest["finished"] is None


def test_a_full_disk_stops_the_run_at_once_names_the_path_and_is_recorded(monkeypatch, tmp_path, capsys):
    """The first "no space left on device" stops the run: no later unit trains for nothing; one line names
    where and how to resume; run.json says why it stopped (issue 58, item 3)."""
    import errno
    import tempfile

    calls, real_unit, real_mkstemp = [], units.run_unit, tempfile.mkstemp

    def counting(*a, **kw):
        calls.append(a[0].name)
        return real_unit(*a, **kw)

    def full(*a, dir=None, **kw):
        if "units" in str(dir):
            raise OSError(errno.ENOSPC, "No space left on device")
        return real_mkstemp(*a, dir=dir, **kw)

    monkeypatch.setattr(units, "run_unit", counting)
    monkeypatch.setattr(tempfile, "mkstemp", full)
    two = ["--profile", "smoke", "--claims", "dp_loss", "--frameworks", "jax", "--quiet"]   # two units, two chains
    assert main(["run", *two, "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"no space left on the device of {tmp_path / 'units'}" in err, err
    assert err.rstrip().endswith("run the same command again to resume")
    assert len(calls) == 1
    manifest = json.loads((tmp_path / "run.json").read_text())
    assert manifest["stopped"]["reason"] == "no space left on device" and "units" in manifest["stopped"]["path"]


def test_repairs_are_named_and_every_run_record_is_kept(tmp_path, caplog):
    kw = dict(profile="smoke", out=tmp_path, claims=["dp_loss"], frameworks=("jax",), models=["baseline"],
              progress=False)
    runner.run(**kw)
    first = json.loads((tmp_path / "run.json").read_text())
    (f,) = tmp_path.glob("units/*/*/*/seed*/result.json")
    f.write_text(f.read_text().replace('"status"', '"statuz"'))
    with caplog.at_level("WARNING", logger="lagbench"):
        summary = runner.run(**kw)
    assert summary["repaired"] == [f"dp_loss/jax/baseline/seed1000: {f}: checksum mismatch"]
    assert "redoing dp_loss/jax/baseline/seed1000" in caplog.text
    assert json.loads((tmp_path / "run.json").read_text())["repaired"] == summary["repaired"]
    (kept,) = (tmp_path / "runs").glob("run-*.json")
    assert json.loads(kept.read_text()) == first
