"""The speed study's tiny preset, run once per session and shared by the tests that read its files
(`test_speed_study.py`) and those that resume from its checkpoints (`test_bench_resume.py`, on copies).
Tests must not write into it."""
import json

import pytest

from lagbench.files.results import write_npz
from lagbench.models import ModelSpec, init_params
from lagbench.replication.training.protocol import Data, Protocol
from lagbench.speedstudy import run_bench

PROTOCOL = Protocol(data=Data("double_pendulum_iid", n_train=64), steps=10, batch=8).to_dict()


def _fake_trained_unit(out):
    """A double-pendulum unit as `lagbench run` leaves it: result.json with model_spec + checkpoint.npz."""
    spec = ModelSpec(kind="lnn", dof=2, hidden=(8,), angle_wrap=True)
    unit = out / "units" / "dp_loss" / "jax" / "lnn" / "seed0"
    unit.mkdir(parents=True)
    write_npz(unit / "checkpoint.npz", init_params(spec, seed=3))
    (unit / "result.json").write_text(json.dumps({
        "claim": "dp_loss", "framework": "jax", "model": "lnn", "seed": 0, "status": "ok",
        "model_spec": spec.to_dict(), "protocol": PROTOCOL}))


def _fake_training_cache(out):
    """An LNN in the training cache (OUT/trained/jax/<key>/) as `replication.training.train` leaves it; the
    baseline is missing, so the rollout study trains a tiny one."""
    spec = ModelSpec(kind="lnn", dof=2, hidden=(8,), angle_wrap=True)
    folder = out / "trained" / "jax" / "fakekey"
    folder.mkdir(parents=True)
    write_npz(folder / "checkpoint.npz", init_params(spec, seed=4))
    (folder / "result.json").write_text(json.dumps({
        "failure": None, "steps_done": 10, "batch": 8, "spec": spec.to_dict(), "seed": 0,
        "protocol": PROTOCOL}))


@pytest.fixture(scope="session")
def bench_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("bench")
    _fake_trained_unit(out)
    _fake_training_cache(out)
    targets = run_bench(out, tiny=True, progress=False)
    return out, targets
