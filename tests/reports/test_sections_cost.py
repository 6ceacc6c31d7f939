"""The measured "Where the time went" section: worker and training hours by claim and by claim, model and
framework from the units' own times (a training read from the cache counted once), and the sittings' wall time
from run.json and runs/."""
from __future__ import annotations

import json
import shutil

import pytest
from result_fixtures import checksum, write_json, write_results

from lagbench.reports.document import Table
from lagbench.reports.load import load_results
from lagbench.reports.sections_cost import cost_sections


def _tables(sections) -> dict:
    return {b.title: b.df for s in sections for b in s.blocks if isinstance(b, Table)}


def test_a_training_two_claims_read_counts_once_on_the_unit_that_trained(small_results_dir, tmp_path):
    root = tmp_path / "r"
    shutil.copytree(small_results_dir, root)
    # claim 2 reads claim 1's models: its units took half a second each, claim 1's trained and evaluated
    for p in root.glob("units/*/*/*/seed*/result.json"):
        d = json.loads(p.read_text())
        if d["checksum"] != checksum(d):   # the fixture's corrupt unit stays as it is
            continue
        d["wall_time_s"] = 0.5 if d["claim"] == "dp_energy" else 10.0 + d["train_time_s"]
        d["checksum"] = checksum(d)
        write_json(p, d)
    res = load_results(root)
    tables = _tables(cost_sections(res))
    by_claim = tables["Time by claim (measured; the costliest first)"].set_index("claim")
    assert list(by_claim.index) == ["dp_loss", "dp_energy"]   # the costliest first
    for claim, row in by_claim.iterrows():
        units = [u for u in res.units if u.claim == claim]
        assert row["units"] == len(units)
        assert float(row["worker h"]) == pytest.approx(sum(u.result["wall_time_s"] for u in units) / 3600, rel=1e-2)
    assert float(by_claim.loc["dp_energy", "training h"]) == 0
    dp_loss = [u for u in res.units if u.claim == "dp_loss"]
    assert float(by_claim.loc["dp_loss", "training h"]) == pytest.approx(sum(u.result["train_time_s"] for u in dp_loss)
                                                                        / 3600, rel=1e-2)
    detail = tables["Time by claim, model and framework"]
    assert detail["units"].sum() == len(res.units)
    assert set(detail["framework"]) == {"jax", "torch"}


def test_sittings_add_up_over_runs_records(small_results_dir, tmp_path):
    root = tmp_path / "r"
    shutil.copytree(small_results_dir, root)
    run = json.loads((root / "run.json").read_text())
    (root / "runs").mkdir()
    (root / "runs" / "run-1.json").write_text(json.dumps({**run, "finished": None, "interrupted": "x",
                                                           "wall_time_s": 5400.0, "units_run": 3, "jobs": 2}))
    (root / "run.json").write_text(json.dumps({**run, "wall_time_s": 1800.0, "units_run": 4, "jobs": 2}))
    sections = cost_sections(load_results(root))
    runs = _tables(sections)["The run's sittings"]
    assert list(runs["ended"]) == ["interrupted", "finished"]
    assert [float(v) for v in runs["wall h"]] == [1.5, 0.5]
    assert "2.00 h of wall time over 2 sittings" in sections[0].blocks[0].text


def test_nothing_without_timed_units(tmp_path):
    assert cost_sections(load_results(tmp_path)) == []
    root = write_results(tmp_path / "r", only=("dp_loss",))
    for p in root.glob("units/*/*/*/seed*/result.json"):
        p.unlink()
    assert cost_sections(load_results(root)) == []


def test_the_report_has_the_section(built):
    assert "Where the time went" in built["markdown"].read_text()
