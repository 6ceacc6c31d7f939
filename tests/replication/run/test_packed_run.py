"""`lagbench run --pack-seeds N` (`replication.run.packing`): a model's seeds train as one program, each stored
under the training key of its run alone, with the same numbers in float64 (to rounding) as the run unpacked; the
records say packed; a rerun, packed or not, trains nothing; a protocol with a `gpu_cohorts.blocker` trains as it
registers; an interrupted program resumes from its snapshot. On the CPU, with a claim's smoke protocol in float64."""
import json
import logging
import shutil
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from lagbench.files import results as R
from lagbench.models.spec import USER_KIND
from lagbench.replication.claims import get
from lagbench.replication.run import chains as C
from lagbench.replication.run import packing
from lagbench.replication.run.gpu_cohorts import MAX_MEMBERS, blocker
from lagbench.replication.run.runner import plan, run
from lagbench.replication.run.splits import RUN_DEFAULT
from lagbench.replication.run.verify import TIMING
from lagbench.replication.training import device as dev
from lagbench.replication.training import train as training

CLAIM, MODELS, SEEDS = "hnn_energy", ["hnn_spring"], 3
TOL = 1e-10   # relative: the packed program's numbers against the runs alone


@pytest.fixture(scope="module")
def float64():
    with pytest.MonkeyPatch.context() as mp:
        claim = get(CLAIM)
        mp.setitem(claim.protocols, "smoke", claim.protocols["smoke"].replace(dtype="float64"))
        yield


def _run(out, fw, pack, **kw):
    return run(profile="smoke", out=out, claims=[CLAIM], frameworks=(fw,), models=MODELS, seeds=SEEDS,
               progress=False, pack_seeds=pack, **kw)


@pytest.fixture(scope="module", params=["jax", pytest.param("torch", marks=pytest.mark.slow)])
def runs(request, float64, tmp_path_factory):
    """(framework, the folder run unpacked, the folder run with the seeds packed 3 to a program)."""
    fw, root = request.param, tmp_path_factory.mktemp(f"packed-{request.param}")
    _run(root / "alone", fw, 1)
    _run(root / "packed", fw, SEEDS)
    return fw, root / "alone", root / "packed"


def _records(out) -> dict:
    return {f.parent.relative_to(out).as_posix(): R.load_result(f.parent)
            for f in sorted(out.glob("units/*/*/*/seed*/result.json"))}


def _trained(out, fw) -> dict:
    return {f.name: f for f in sorted((out / "trained" / fw).iterdir())}


def _close(a, b) -> bool:
    a, b = np.asarray(a, float), np.asarray(b, float)
    scale = np.maximum(np.abs(a), np.abs(b))
    return a.shape == b.shape and bool(np.all(np.abs(a - b) <= TOL * np.where(scale > 0, scale, 1.0)))


def _same_training(a, b) -> None:
    pa, pb = R.load_npz(a / "checkpoint.npz"), R.load_npz(b / "checkpoint.npz")
    assert sorted(pa) == sorted(pb) and all(_close(pa[k], pb[k]) for k in pa)
    la, lb = pd.read_csv(a / "train_log.csv"), pd.read_csv(b / "train_log.csv")
    assert list(la["step"]) == list(lb["step"]) and _close(la["loss"], lb["loss"])
    assert _close(la["grad_norm"], lb["grad_norm"])


def test_packed_seeds_store_the_numbers_of_their_runs_alone_under_the_same_keys(runs):
    fw, alone, packed = runs
    ta, tp = _trained(alone, fw), _trained(packed, fw)
    assert sorted(ta) == sorted(tp) and len(ta) == SEEDS   # each seed under the key of its run alone
    for key in ta:
        _same_training(ta[key], tp[key])
        assert json.loads((ta[key] / "result.json").read_text())["cohort"] is None
        assert not (tp[key] / "inflight").exists()   # the program's snapshots cleared once stored
    ra, rp = _records(alone), _records(packed)
    assert sorted(ra) == sorted(rp) and len(ra) == SEEDS
    seeds = sorted(r["seed"] for r in rp.values())
    for name, a in ra.items():
        p = rp[name]
        assert a["cohort"] is None and p["cohort"] == {"seeds": seeds, "packed": True}
        assert p["protocol"] == a["protocol"] and p["protocol"]["cohort"] is None and p["status"] == a["status"]
        _same_training(alone / name, packed / name)
        values = {k: v for k, v in a["metrics"].items() if not TIMING.search(k)}
        assert values and sorted(p["metrics"]) == sorted(a["metrics"])
        assert all(_close(v, p["metrics"][k]) for k, v in values.items() if v is not None), name
    assert json.loads((packed / "run.json").read_text())["pack_seeds"] == {fw: SEEDS}


@pytest.mark.parametrize("pack", [SEEDS, 1])
def test_a_rerun_packed_or_not_reads_the_packed_trainings(runs, tmp_path, monkeypatch, pack):
    fw, _, packed = runs
    out = tmp_path / "again"
    shutil.copytree(packed / "trained", out / "trained")   # the trainings kept, the units to make again

    def boom(*a, **k):
        raise AssertionError("retrained a stored training")
    for module, name in ((training, "run_training"), (training, "train_cohort"), (packing, "train_cohort")):
        monkeypatch.setattr(module, name, boom)
    summary = _run(out, fw, pack)
    assert summary["errors"] == []
    again, before = _records(out), _records(packed)
    assert sorted(again) == sorted(before)
    for name, d in again.items():
        assert d["cohort"] == before[name]["cohort"]
        assert {k: v for k, v in d["metrics"].items() if not TIMING.search(k)} == {
            k: v for k, v in before[name]["metrics"].items() if not TIMING.search(k)}


def test_a_protocol_with_restarts_trains_each_seed_alone(tmp_path, monkeypatch):
    units = plan("smoke", claims=["dp_loss"], frameworks=("jax",), models=["baseline"], seeds=2, split=RUN_DEFAULT)
    assert "restarts" in blocker(units[0].protocol())
    assert "user's model" in blocker(units[0].protocol().replace(scouting=None), SimpleNamespace(kind=USER_KIND))
    assert packing.by_unit(units, tmp_path, {"jax": 2}) == {}

    def boom(*a, **k):
        raise AssertionError("packed a protocol with restarts")
    monkeypatch.setattr(packing, "train_cohort", boom)
    summary = run(profile="smoke", out=tmp_path, claims=["dp_loss"], frameworks=("jax",), models=["baseline"],
                  seeds=2, progress=False, pack_seeds=2)
    assert summary["errors"] == []
    assert [d["cohort"] for d in _records(tmp_path).values()] == [None, None]


def test_a_packed_program_is_one_chain_and_resumes_from_its_snapshot(runs, tmp_path, monkeypatch, caplog):
    fw, alone, _ = runs
    units = plan("smoke", claims=[CLAIM, "dp_loss"], frameworks=(fw,), models=[*MODELS, "baseline"], seeds=SEEDS,
                 split=RUN_DEFAULT)   # `run`'s seeds, those of the runs compared with
    packed = [u for u in units if u.claim.id == CLAIM]
    chains = packing.chains(units, tmp_path, {fw: SEEDS})
    assert sorted(len(c) for c in chains) == [1] * (len(units) - SEEDS) + [SEEDS]
    assert {u.name for c in chains if len(c) == SEEDS for u in c} == {u.name for u in packed}
    assert [[u.name for u in c] for c in packing.chains(units, tmp_path, {fw: 1})] == [
        [u.name for u in c] for c in C.chains(units)]

    store = packing._store

    def cut(folder, *a):   # the program ends, then the run is cut before the first seed is stored
        raise RuntimeError("cut")
    monkeypatch.setattr(packing, "_store", cut)
    refs = [C.ref(u) for u in packed]
    done = packing.run_chain(refs, tmp_path, {fw: SEEDS})
    assert all(error and "RuntimeError: cut" in error for _, _, error in done)
    assert list(tmp_path.glob(f"trained/{fw}/*/inflight/{packing.PHASE}.json"))
    monkeypatch.setattr(packing, "_store", store)
    with caplog.at_level(logging.INFO, logger="lagbench"):
        assert all(error is None for _, _, error in packing.run_chain(refs, tmp_path, {fw: SEEDS}))
    assert "resuming a training from its snapshot" in caplog.text
    ta, tb = _trained(alone, fw), _trained(tmp_path, fw)
    assert sorted(ta) == sorted(tb) and not list(tmp_path.glob(f"trained/{fw}/*/inflight"))
    for key in ta:
        _same_training(ta[key], tb[key])


def test_pack_seeds_is_checked_and_off_on_the_cpu_unless_asked(monkeypatch):
    monkeypatch.setenv(dev.ENV, "cpu")
    assert packing.members(None, ["jax", "torch"]) == {"jax": 1, "torch": 1}
    monkeypatch.setattr(dev, "resolve", lambda req, fw: "gpu" if fw == "jax" else "cpu")
    assert packing.members(None, ["jax", "torch"]) == {"jax": MAX_MEMBERS, "torch": 1}
    assert packing.members(4, ["jax"]) == {"jax": 4}
    assert packing.members(None, ["jax"], "ray") == {"jax": 1}
    for bad, executor in ((0, "local"), (2.5, "local"), (2, "ray")):
        with pytest.raises(ValueError, match="--pack-seeds"):
            packing.members(bad, ["jax"], executor)
