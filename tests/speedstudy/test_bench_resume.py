"""`lagbench bench --resume`: a resumed run takes every stage an earlier run finished from its checkpoint
(OUT/bench/stages/) and writes the same files; a checkpoint of another commit, or one that does not parse,
is named on stderr and its stage runs again. The tiny preset; nothing is timed."""
import json
import shutil

import pytest

from lagbench import speedstudy as B
from lagbench.speedstudy import inference as INF
from lagbench.speedstudy import (
    latency,
    members,
    rollout,
    roofline,
    scaling,
    structure,
    train_target,
    training,
)
from lagbench.speedstudy.resume import StageCache

STAGES = ["inference", "single-sample latency", "training", "rollouts", "scaling", "fast vs paper", "structure",
          "train to target", "members"]
# the work each stage calls; a stage that runs again on resume reaches one of these
WORK = {"inference": (INF, "run_case"), "single-sample latency": (latency, "latency_rows"),
        "training": (training, "training_rows"), "rollouts": (rollout, "rollout_rows"),
        "scaling": (scaling, "run_scaling_group"), "fast vs paper": (roofline, "roofline_rows"),
        "structure": (structure, "structure_rows"), "train to target": (train_target, "train_target_rows"),
        "members": (members, "members_rows")}
SAME = ["inference", "latency", "training", "rollout", "scaling", "scaling_fit", "fast_paper", "matmul",
        "structure", "train_target", "train_target_log", "members", "ratios"]


@pytest.fixture(scope="module")
def first_run(bench_dir):
    return bench_dir[0]  # the session's tiny run (conftest.py); the tests resume into copies of it


def _forbid(monkeypatch, stages):
    def boom(*a, **k):
        raise AssertionError("this stage should have come from its checkpoint")
    for st in stages:
        monkeypatch.setattr(*WORK[st], boom)


def _files(out):
    files = {f: (out / "bench" / f"{f}.csv").read_bytes() for f in SAME}
    files["targets"] = (out / "bench" / "targets.json").read_bytes()
    return files


def test_every_stage_is_checkpointed_and_a_resumed_run_writes_the_same_files(first_run, tmp_path, monkeypatch):
    assert sorted(p.stem for p in (first_run / "bench" / "stages").glob("*.json")) == \
        sorted(s.replace(" ", "_") for s in STAGES)
    out = tmp_path / "copy"
    shutil.copytree(first_run, out)
    _forbid(monkeypatch, STAGES)
    B.run_bench(out, tiny=True, progress=False, resume=True)
    assert _files(out) == _files(first_run)
    assert json.loads((out / "bench" / "timings.json").read_text())["resumed_stages"] == STAGES


def test_stale_or_corrupt_checkpoints_run_again_and_say_so(first_run, tmp_path, monkeypatch, capsys):
    out = tmp_path / "copy"
    shutil.copytree(first_run, out)
    stages = out / "bench" / "stages"
    # two of the quickest stages: what is checked is the checkpoint, not the stage
    (stages / "fast_vs_paper.json").write_text('{"tables": ')  # cut off
    d = json.loads((stages / "training.json").read_text())
    (stages / "training.json").write_text(json.dumps({**d, "commit": "0000000"}))
    _forbid(monkeypatch, [s for s in STAGES if s not in ("fast vs paper", "training")])
    B.run_bench(out, tiny=True, progress=False, resume=True)
    err = capsys.readouterr().err
    assert "fast_vs_paper.json is unreadable" in err and "at commit 0000000" in err
    resumed = json.loads((out / "bench" / "timings.json").read_text())["resumed_stages"]
    assert resumed == [s for s in STAGES if s not in ("fast vs paper", "training")]
    assert json.loads((stages / "fast_vs_paper.json").read_text())["tables"]["fast_paper"]  # rewritten


def test_without_resume_every_stage_runs(first_run, tmp_path):
    cache = StageCache(first_run / "bench", "tiny", "any", resume=False)
    assert all(cache.load(s) is None for s in STAGES)


def test_checkpoints_keep_nan_and_infinities(tmp_path):
    cache = StageCache(tmp_path, "tiny", "abc", resume=True)
    rows = [{"a": float("nan"), "b": float("inf"), "c": None, "d": {"mm": 3}}]
    cache.save("x y", {"t": rows}, ["a note"])
    tables, notes = cache.load("x y")
    r = tables["t"][0]
    assert r["a"] != r["a"] and r["b"] == float("inf") and r["c"] is None and r["d"] == {"mm": 3}
    assert notes == ["a note"] and cache.reused == ["x y"]
    assert StageCache(tmp_path, "quick", "abc", resume=True, warn=lambda m: None).load("x y") is None
