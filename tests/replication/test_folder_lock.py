"""Two commands never write into one folder at once (issue 58, item 1): every command that writes a folder
holds its lock (`results.output_folder`, let go by `results.writing` when the command ends); a second one
is refused with one line naming the holder, before it writes anything."""
import os
import signal
import subprocess
import sys
import time

import numpy as np

from lagbench.files import results as R
from lagbench.replication.fit.task import fit


def _data(path):
    rng = np.random.default_rng(0)
    q, qdot = rng.normal(size=(40, 1)), rng.normal(size=(40, 1))
    np.savez(path, q=q, qdot=qdot, qddot=-9.81 * np.sin(q))
    return path


def _fit_cli(data, out, steps=2):
    return [sys.executable, "-m", "lagbench", "fit", "--data", str(data), "--model", "baseline",
            "--steps", str(steps), "--hidden", "8", "--batch", "16", "--restarts", "0", "--frameworks", "torch",
            "--quiet", "--device", "cpu", "--out", str(out)]


def test_a_second_writer_is_refused_in_one_line_and_writes_nothing(tmp_path):
    data, out = _data(tmp_path / "d.npz"), tmp_path / "out"
    with R.writing():
        R.output_folder(out)
        R.output_folder(out)   # reentrant within a process
        r = subprocess.run(_fit_cli(data, out), capture_output=True, text=True, timeout=300)
        assert r.returncode == 2, r.stderr
        lines = r.stderr.strip().splitlines()
        assert len(lines) == 1 and "another lagbench command is writing into this folder" in lines[0]
        assert f"pid {os.getpid()}" in lines[0]
        assert sorted(p.name for p in out.iterdir()) == [R.LOCK_NAME]
    r = subprocess.run(_fit_cli(data, out), capture_output=True, text=True, timeout=300)   # let go: it runs
    assert r.returncode == 0 and r.stdout.startswith(("ok:", "done:")), r.stderr


def test_a_library_call_lets_go_of_its_folder_when_it_returns(tmp_path):
    fit(_data(tmp_path / "d.npz"), model="baseline", out=tmp_path / "out", steps=2, hidden=(8,), batch=16)
    assert not [k for k in R._LOCKS if k.startswith(str(tmp_path.resolve()))]


def test_two_fits_into_one_folder_at_once_never_both_report_success(tmp_path):
    """The second starts while the first holds the folder: it is refused, and the folder holds the first
    fit alone, whole."""
    data, out = _data(tmp_path / "d.npz"), tmp_path / "out"
    # the first is paused (SIGSTOP) as soon as it holds the folder, so that it is still mid-fit however long
    # the second takes to start, import and ask; then it goes on and ends (seconds of training)
    first = subprocess.Popen(_fit_cli(data, out, steps=5_000), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                             text=True)
    deadline = time.time() + 120
    while time.time() < deadline and f"pid {first.pid}" not in ((out / R.LOCK_NAME).read_text()
                                                                  if (out / R.LOCK_NAME).exists() else ""):
        time.sleep(0.01)
    first.send_signal(signal.SIGSTOP)
    try:
        second = subprocess.run(_fit_cli(_data(tmp_path / "e.npz"), out), capture_output=True, text=True,
                                timeout=300)
    finally:
        first.send_signal(signal.SIGCONT)
    stdout, stderr = first.communicate(timeout=300)
    assert first.returncode == 0, stderr
    assert second.returncode == 2 and f"pid {first.pid}" in second.stderr, second.stderr
    assert len(list(out.glob("units/fit/*/*/seed*/result.json"))) == 1


def test_a_run_into_a_locked_folder_is_refused_before_it_plans(tmp_path, monkeypatch):
    """`lagbench run` plans every claim's units before it takes its folder; a folder another command holds
    is refused first, with the same line, and planning never starts."""
    from lagbench.replication.run import runner

    out = tmp_path / "out"
    holder = subprocess.Popen([sys.executable, "-c", "import sys, time; from lagbench.files import results as R\n"
                               "with R.writing():\n    R.output_folder(sys.argv[1]); print('held', flush=True); "
                               "time.sleep(60)", str(out)], stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "held"
        monkeypatch.setattr(runner, "plan", lambda *a, **k: (_ for _ in ()).throw(AssertionError("planned")))
        try:
            runner.run("smoke", out=out, claims=["dp_loss"], progress=False)
            raise AssertionError("not refused")
        except ValueError as e:
            assert "another lagbench command is writing into this folder" in str(e) and f"pid {holder.pid}" in str(e)
        R.refuse_if_locked(tmp_path / "absent")   # no folder, or no lock file: nothing to refuse, nothing made
        assert not (tmp_path / "absent").exists()
    finally:
        holder.kill()
        holder.wait()
        holder.stdout.close()
    R.refuse_if_locked(out)   # let go: no refusal
