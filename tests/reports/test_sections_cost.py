"""The measured "Where the time went" section: worker and training hours by claim and by claim, model and
framework from the units' own times (a training read from the cache counted once), and the sittings' wall time
from run.json and runs/."""
from __future__ import annotations

import json
import shutil

import pytest
from result_fixtures import write_results

from lagbench.reports.document import Table
from lagbench.reports.load import load_results
from lagbench.reports.sections_cost import cost_sections


def _tables(sections) -> dict:
    return {b.title: b.df for s in sections for b in s.blocks if isinstance(b, Table)}


def test_hours_by_claim_count_a_cached_training_once(results_dir):
    res = load_results(results_dir)
    tables = _tables(cost_sections(res))
    by_claim = tables["Time by claim (measured; the costliest first)"].set_index("claim")
    assert sorted(by_claim.index) == sorted({u.claim for u in res.units})
    for claim, row in by_claim.iterrows():
        assert row["units"] == sum(u.claim == claim for u in res.units)
    # the fixture's units: wall 2 s each; seed 0 trained 1.5 s itself, seed 1 records 2.5 s of training it read
    units = res.units
    worker_h = sum(float(u.result["wall_time_s"]) for u in units) / 3600
    train_h = sum(float(u.result["train_time_s"]) for u in units
                  if float(u.result["wall_time_s"]) >= float(u.result["train_time_s"])) / 3600
    assert by_claim["worker h"].sum() == pytest.approx(worker_h, abs=0.01)
    assert by_claim["training h"].sum() == pytest.approx(train_h, abs=0.01)
    assert by_claim["training h"].sum() < sum(float(u.result["train_time_s"]) for u in units) / 3600
    detail = tables["Time by claim, model and framework"]
    assert detail["units"].sum() == len(units)
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
    assert list(runs["wall h"]) == [1.5, 0.5]
    assert "2.00 h of wall time over 2 sittings" in sections[0].blocks[0].text


def test_nothing_without_timed_units(tmp_path):
    assert cost_sections(load_results(tmp_path)) == []
    root = write_results(tmp_path / "r", only=("dp_loss",))
    for p in root.glob("units/*/*/*/seed*/result.json"):
        p.unlink()
    assert cost_sections(load_results(root)) == []


def test_the_report_has_the_section(built):
    assert "Where the time went" in built["markdown"].read_text()
