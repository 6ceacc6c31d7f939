"""`lagbench verify`: units retrained from scratch match the stored ones bit for bit on the machine that made
them; a stored value tampered with is shown as a difference (exit status 1); the report says how many units
were re-verified, where and when."""
import json
import shutil

import pandas as pd
import pytest

from lagbench.cli import main
from lagbench.files import results as R
from lagbench.replication.run import verify as V
from lagbench.replication.run.runner import run


@pytest.fixture(scope="module")
def two_units(tmp_path_factory):
    out = tmp_path_factory.mktemp("verify") / "results"
    run(profile="smoke", out=out, claims=["dp_loss"], frameworks=("jax",), models=["baseline"], seeds=2,
        progress=False)
    assert len(list(out.glob("units/*/*/*/seed*/result.json"))) == 2
    return out


def test_two_retrained_units_are_identical_to_the_stored_ones(two_units, tmp_path):
    out = tmp_path / "results"
    shutil.copytree(two_units, out)
    rows = V.verify(out, 2, seed=3, progress=False)
    assert rows["unit"].nunique() == 2 and (rows["outcome"] == "identical").all()
    assert rows["same_environment"].all() and (rows["tolerance"] == V.SAME_TOL).all()
    stored = R.load_result(out / "units/dp_loss/jax/baseline/seed1000")
    assert set(stored["metrics"]) | set(V.VALUES) == set(rows[rows["unit"].str.endswith("seed1000")]["value"])
    written = pd.read_csv(out / V.FILE)
    assert len(written) == len(rows)
    assert "2 of 2 units retrained from scratch" in V.summary(rows) and "2 identical" in V.summary(rows)
    V.verify(out, 1, seed=3, progress=False)   # a second verification adds its rows
    assert len(pd.read_csv(out / V.FILE)) > len(rows)


def test_a_wall_time_metric_is_shown_not_compared():
    stored = {"metrics": {"rollout_us_per_step": 10.0, "heldout_l1": 1.0}, "status": "ok"}
    new = {"metrics": {"rollout_us_per_step": 99.0, "heldout_l1": 1.0 + 1e-9}, "status": "ok"}
    rows = {r["value"]: r["outcome"] for r in V.compare(stored, new)}
    assert rows == {**{k: "identical" for k in V.VALUES}, "rollout_us_per_step": "timing", "heldout_l1": "within"}
    assert {r["value"]: r["outcome"] for r in V.compare(stored, {**new, "status": "failed"})}["status"] == "differs"


def test_the_same_seed_picks_the_same_units_and_another_can_pick_others():
    units = list(range(10))
    assert V.pick(units, 3, 1) == V.pick(units, 3, 1)
    assert len({tuple(V.pick(units, 3, s)) for s in range(5)}) > 1


def test_a_tampered_stored_metric_is_a_difference_and_the_report_shows_it(two_units, tmp_path, capsys):
    from lagbench.reports.load import load_results
    from lagbench.reports.sections_verify import verify_sections

    out = tmp_path / "results"
    shutil.copytree(two_units, out)
    folder = out / "units/dp_loss/jax/baseline/seed1001"
    d = R.load_result(folder)
    true = d["metrics"]["heldout_l1"]
    R.write_json(folder / "result.json", {**d, "metrics": {**d["metrics"], "heldout_l1": true * 1.01}}, checksum=True)
    code = main(["verify", "--results", str(out), "--units", "2", "--quiet"])
    printed = capsys.readouterr().out
    assert code == 1 and "1 identical" in printed and "1 differs" in printed
    rows = pd.read_csv(out / V.FILE)
    (bad,) = rows[rows["outcome"] != "identical"].itertuples(index=False)
    assert (bad.unit, bad.value, bad.outcome) == ("dp_loss/jax/baseline/seed1001", "heldout_l1", "differs")
    assert float(bad.recomputed) == true and bad.rel_diff == pytest.approx(0.01 / 1.01)   # a column of mixed values
    assert "seed1001 heldout_l1" in printed
    (section,) = verify_sections(load_results(out))
    text = json.dumps([getattr(b, "text", "") for b in section.blocks])
    assert "2 distinct units" in text
    tables = [b.df for b in section.blocks if hasattr(b, "df")]
    assert tables[0][["units", "identical", "differs"]].values.tolist() == [[2, 1, 1]]
    assert tables[1]["value"].tolist() == ["heldout_l1"]


def test_the_report_has_no_verification_section_without_a_verification(two_units):
    from lagbench.reports.load import load_results
    from lagbench.reports.sections_verify import verify_sections

    assert verify_sections(load_results(two_units)) == []


def test_a_packed_training_retrained_alone_is_held_to_the_tolerance_of_another_environment():
    """Packed seeds (`run --pack-seeds`) multiply stacked: another rounding than the unit's run alone."""
    env = {"framework": "jax", "hardware": {"cpu": "x", "jax_threads": 1}, "versions": {"jax": "1"},
           "train_device": "cpu", "metrics": {"m": 1.0}}
    packed = {**env, "cohort": {"seeds": [0, 1], "packed": True}}
    assert V.same_environment(env, {**env, "cohort": None})
    assert not V.same_environment(packed, env)
    assert {r["tolerance"] for r in V.compare(packed, {**env, "metrics": {"m": 1.01}})} == {V.OTHER_TOL}
    assert V.same_environment(packed, dict(packed))


def test_the_draw_can_be_narrowed_to_claims_frameworks_and_models_and_a_missing_name_is_named(two_units, capsys):
    units, _ = V.candidates(two_units)
    assert V.narrowed(units, {"claims": ("dp_loss",), "models": ("baseline",), "frameworks": None}) == units
    assert V.narrowed(units, None) == units
    with pytest.raises(ValueError, match=r"--frameworks torch: no unit to retrain of torch .*have jax\)"):
        V.narrowed(units, {"frameworks": ("torch",)})
    with pytest.raises(ValueError, match=r"--models baseline,lnn: no unit to retrain of lnn"):
        V.narrowed(units, {"models": ("baseline", "lnn")})
    before = sorted(p.name for p in two_units.rglob("*"))
    code = main(["verify", "--results", str(two_units), "--claims", "rel_coords", "--quiet"])
    err = capsys.readouterr().err
    assert code != 0 and "--claims rel_coords: no unit to retrain of rel_coords" in err
    assert sorted(p.name for p in two_units.rglob("*")) == before   # nothing written


def test_threads_are_part_of_the_environment_and_choose_where_a_unit_retrains():
    """A unit's framework sums in another order on other threads: the same machine at other threads is another
    environment. JAX's pool without a record is the machine's cores (what XLA sizes it to); PyTorch's unknown,
    never the same. A unit trained on one thread, or on PyTorch threads not recorded, retrains in a worker."""
    def rec(fw, **hw):
        return {"framework": fw, "hardware": {"cpu": "x", **hw}, "versions": {}, "train_device": "cpu"}

    assert V.same_environment(rec("jax", jax_threads=1), rec("jax", jax_threads=1, torch_threads=2))
    assert not V.same_environment(rec("jax", jax_threads=1), rec("jax", jax_threads=2))
    assert V.same_environment(rec("jax", cores=2), rec("jax", jax_threads=2, cores=2))
    assert not V.same_environment(rec("jax", cores=2), rec("jax", jax_threads=1, cores=2))
    assert not V.same_environment(rec("torch", cores=2), rec("torch", torch_threads=1))
    assert V.same_environment(rec("torch", torch_threads=1, jax_threads=2), rec("torch", torch_threads=1))
    assert [V.in_worker(r) for r in (rec("jax", jax_threads=1), rec("jax", cores=2), rec("jax", cores=1),
                                     rec("torch"), rec("torch", torch_threads=2))] == [True, False, True, True, False]


def test_pytorch_keeping_subnormal_floats_is_another_environment():
    """A PyTorch unit trained while subnormals were kept (not recorded: kept) rounds otherwise than one trained
    with them flushed (`models.torch.subnormals`): held to the other environment's tolerance. JAX's record
    of PyTorch's setting is no part of a JAX unit's environment."""
    def rec(fw, **hw):
        return {"framework": fw, "hardware": {"cpu": "x", "torch_threads": 1, "jax_threads": 1, **hw},
                "versions": {}, "train_device": "cpu", "metrics": {"m": 1.0}}

    flushed = rec("torch", torch_subnormals="flushed")
    assert V.same_environment(flushed, rec("torch", torch_subnormals="flushed"))
    assert not V.same_environment(flushed, rec("torch"))
    assert not V.same_environment(flushed, rec("torch", torch_subnormals="kept"))
    assert V.same_environment(rec("torch"), rec("torch", torch_subnormals="kept"))
    assert {r["tolerance"] for r in V.compare(rec("torch"), {**flushed, "metrics": {"m": 1.01}})} == {V.OTHER_TOL}
    assert V.same_environment(rec("jax"), rec("jax", torch_subnormals="flushed"))


def test_a_unit_trained_in_a_worker_retrains_in_one(two_units, tmp_path, monkeypatch):
    folder = tmp_path / "results"
    shutil.copytree(two_units, folder)
    calls, real = [], V.run_units
    monkeypatch.setattr(V, "run_units", lambda part, *a, **kw: calls.append(([u.name for u in part], kw)) or
                        real(part, *a, **kw))
    unit = next(folder.glob("units/*/*/*/seed*/result.json")).parent
    d = R.load_result(unit)
    R.write_json(unit / "result.json", {**d, "hardware": {**d["hardware"], "jax_threads": 1}}, checksum=True)
    other = [f.parent for f in folder.glob("units/*/*/*/seed*/result.json") if f.parent != unit]
    for o in other:   # the other unit at two threads: retrained here
        d = R.load_result(o)
        R.write_json(o / "result.json", {**d, "hardware": {**d["hardware"], "jax_threads": 2}}, checksum=True)
    V.verify(folder, 2, progress=False)
    name = lambda f: "/".join(f.relative_to(folder / "units").parts)   # noqa: E731
    assert [(names, kw["workers"]) for names, kw in calls] == [([name(o) for o in other], False),
                                                               ([name(unit)], True)]
