"""The control-rate stage of `lagbench bench` (`speedstudy.control_rate`): one run of the stage alone at 0.1
simulated seconds per loop (its own process, as the quick preset runs it), its rows, its checkpoint, and the
report's table. No wall-clock limit is asserted: only how the numbers relate."""
import json
import math
import shutil
from dataclasses import replace

import pandas as pd
import pytest

from lagbench.reports.document import Table
from lagbench.reports.load import BENCH_COLUMNS, load_results
from lagbench.reports.sections_speed import speed_sections
from lagbench.speedstudy import bench as BENCH
from lagbench.speedstudy import control_rate as CR
from lagbench.speedstudy.timing import FULL, GPU, QUICK, STAGES, TINY

SECONDS = 0.1   # 50 ticks per loop, the first 25 left out
TITLE = "Control-loop rate on one core (the DeLaN paper's robot: 500 Hz)"


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    out = tmp_path_factory.mktemp("control_rate")
    BENCH.run_bench(out, sizes=replace(TINY, stages=("control rate",), control_s=SECONDS), progress=False)
    return out


@pytest.fixture(scope="module")
def rows(run):
    return json.loads((run / "bench" / "stages" / "control_rate.json").read_text())["tables"]["control_rate"]


def test_presets():
    assert "control rate" in STAGES and QUICK.control_s > 0 and FULL.control_s >= QUICK.control_s
    assert TINY.control_s == 0 and "control rate" not in GPU.stages


def test_rows_columns_and_counts(run, rows):
    assert len(rows) == 2 * 2 * 2 and all(list(r) == CR.COLUMNS for r in rows)
    assert {(r["model"], r["framework"], r["mode"]) for r in rows} == \
        {(m, fw, mode) for m in CR.MODELS for fw in CR.FRAMEWORKS for mode in CR.MODES}
    assert all(r["ticks"] == 25 and r["warmup"] == 25 and r["seconds"] == SECONDS for r in rows)
    assert all(r["threads"] == 1 and r["jax_dispatch"] == "sync" and r["hidden"] == "64x64" for r in rows)
    csv = pd.read_csv(run / "bench" / "control_rate.csv")
    assert list(csv.columns) == CR.COLUMNS and len(csv) == len(rows)


def test_learning_adds_its_time_to_inference(rows):
    by = {(r["model"], r["framework"], r["mode"]): r for r in rows}
    for m in CR.MODELS:
        for fw in CR.FRAMEWORKS:
            inf, both = by[m, fw, "inference"], by[m, fw, "inference+learning"]
            assert inf["learning_us_mean"] == 0 and inf["mean_us"] == pytest.approx(inf["inference_us_mean"])
            assert both["learning_us_mean"] > 0
            assert both["mean_us"] == pytest.approx(both["inference_us_mean"] + both["learning_us_mean"])
            assert both["median_us"] > 0.5 * inf["median_us"]   # an optimiser step costs more than a call


def test_rates_and_fits_flags_follow_the_numbers(rows):
    for r in rows:
        assert 0 < r["median_us"] <= r["p99_us"]
        assert r["rate_hz_mean"] == pytest.approx(1e6 / r["mean_us"])
        assert r["rate_hz_p99"] == pytest.approx(1e6 / r["p99_us"])
        assert r["fits_500hz_mean"] == (r["mean_us"] < 2000) == (r["rate_hz_mean"] > 500)
        assert r["fits_500hz_p99"] == (r["p99_us"] < 2000) == (r["rate_hz_p99"] > 500)


def test_resume_takes_the_stage_from_its_checkpoint(run, tmp_path, monkeypatch):
    out = tmp_path / "copy"
    shutil.copytree(run, out)
    monkeypatch.setattr(CR, "control_rate_stage", lambda *a, **k: pytest.fail("the stage ran again"))
    BENCH.run_bench(out, sizes=replace(TINY, stages=("control rate",), control_s=SECONDS), progress=False,
                    resume=True)
    assert json.loads((out / "bench" / "timings.json").read_text())["resumed_stages"] == ["control rate"]
    assert (out / "bench" / "control_rate.csv").read_bytes() == (run / "bench" / "control_rate.csv").read_bytes()


def test_warmup_must_leave_ticks_to_measure():
    with pytest.raises(ValueError, match="warmup 50 ticks"):
        CR.control_rate_rows(seconds=SECONDS, warmup=50)


def test_report_shows_the_table(tmp_path, rows):
    bench = tmp_path / "results" / "bench"
    bench.mkdir(parents=True)
    pd.DataFrame(rows).to_csv(bench / "control_rate.csv", index=False)
    res = load_results(tmp_path / "results")
    assert set(BENCH_COLUMNS["control_rate"]) <= set(CR.COLUMNS)
    assert "control_rate" in res.bench and not [p for p in res.problems if "control_rate" in p]
    tables = [b for s in speed_sections(res, tmp_path / "report") for b in s.blocks
              if isinstance(b, Table) and b.title == TITLE]
    assert len(tables) == 1 and tables[0].sources == ["bench/control_rate.csv"] and tables[0].note
    t = tables[0].df
    assert len(t) == len(rows) and set(t["mode"]) == set(CR.MODES)
    assert set(t["fits_500hz_mean"]) <= {"yes", "no"} and not math.isnan(float(t["mean_us"].iloc[0]))
