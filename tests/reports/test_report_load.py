"""Reading and validating result files: checksums, corrupt units, missing pieces, bench files."""

import json

import pandas as pd
from result_fixtures import CORRUPT, NOT_RUN_CLAIM, checksum, write_results

from lagbench.reports.integrity import canonical_json, result_checksum
from lagbench.reports.load import load_results


def test_canonical_form_is_sorted_compact_json_without_checksum():
    d = {"b": 1, "a": {"d": 2.5, "c": [1, 2]}, "checksum": "x"}
    assert canonical_json(d) == '{"a":{"c":[1,2],"d":2.5},"b":1}'
    assert result_checksum(d) == result_checksum({k: v for k, v in d.items() if k != "checksum"})


def test_fixture_units_verify_and_corrupt_one_is_flagged(results_dir):
    res = load_results(results_dir)
    corrupt = [u for u in res.units if u.status == "corrupt"]
    assert [(u.claim, u.framework, u.model, u.seed) for u in corrupt] == [(*CORRUPT[:3], str(CORRUPT[3]))]
    assert "checksum" in corrupt[0].reason
    assert all(u.status == "ok" for u in res.units if u not in corrupt)
    assert not res.usable(NOT_RUN_CLAIM)
    assert [c["number"] for c in res.claims] == list(range(1, 11))
    assert set(res.bench) == {"inference", "training", "scaling", "ratios"}
    # the fixture's verdicts.json says "reproduced" everywhere; the unit files say otherwise
    assert len(res.problems) == 1 and res.problems[0].startswith("summary/verdicts.json disagrees")


def test_tampered_listed_file_marks_unit_corrupt(tmp_path):
    write_results(tmp_path)
    log = tmp_path / "units/dp_energy/jax/lnn/seed0/train_log.csv"
    log.write_text(log.read_text() + "999,1,1,1,1\n")
    (tmp_path / "units/dp_energy/jax/baseline/seed1/arrays.npz").unlink()
    res = load_results(tmp_path)
    bad = {u.rel: u.reason for u in res.units if u.status == "corrupt"}
    assert bad["units/dp_energy/jax/lnn/seed0"] == "train_log.csv sha256 mismatch"
    assert bad["units/dp_energy/jax/baseline/seed1"] == "listed file arrays.npz missing"


def test_failed_unit_missing_unit_bad_bench_and_garbage_json(tmp_path):
    write_results(tmp_path)
    path = tmp_path / "units/dp_loss/jax/lnn/seed0/result.json"
    r = json.loads(path.read_text())
    r.update(status="failed", failure={"kind": "non_finite_loss", "step": 3, "message": "NaN"})
    r["checksum"] = checksum(r)
    path.write_text(json.dumps(r))
    (tmp_path / "units/dp_loss/jax/baseline/seed1/result.json").unlink()
    (tmp_path / "units/wave_lgn/jax/lgn/seed0/result.json").write_text("{not json")
    pd.DataFrame({"system": ["x"]}).to_csv(tmp_path / "bench/rollout.csv", index=False)
    res = load_results(tmp_path)
    status = {u.rel: (u.status, u.reason) for u in res.units}
    assert status["units/dp_loss/jax/lnn/seed0"] == ("failed", "non_finite_loss")
    assert status["units/wave_lgn/jax/lgn/seed0"][0] == "corrupt"
    assert "units/dp_loss/jax/baseline/seed1" in res.listed_missing
    assert "rollout" not in res.bench and any("rollout.csv" in p for p in res.problems)


def test_missing_and_empty_folders(tmp_path):
    for root in (tmp_path / "absent", tmp_path):
        res = load_results(root)
        assert res.claims == [] and res.units == [] and res.run is None
