"""The cross-framework section (`reports.sections_frameworks`) on the fixture results and on edited copies."""

import json
import math
import re
import shutil
from pathlib import Path

import pandas as pd
import pytest
from result_fixtures import CORRUPT, checksum, sha, write_json

from lagbench.reports.document import Bullets, Table
from lagbench.reports.load import Results, load_results
from lagbench.reports.sections_frameworks import (
    PART,
    START_TOL,
    _flag,
    curve_agreement,
    frameworks_sections,
    training_curves_table,
    verdicts_table,
)


def _tables(section) -> dict:
    return {b.title: b.df for b in section.blocks if isinstance(b, Table)}


def _unit(root: Path, claim, fw, model, seed) -> Path:
    return root / "units" / claim / fw / model / f"seed{seed}"


def _rewrite(udir: Path, log: pd.DataFrame | None = None, **metrics) -> None:
    """Edit a fixture unit's train log or metrics, with its checksums renewed (so it stays usable)."""
    result = json.loads((udir / "result.json").read_text())
    if log is not None:
        log.to_csv(udir / "train_log.csv", index=False)
        result["files"]["train_log.csv"] = sha((udir / "train_log.csv").read_bytes())
    result["metrics"].update(metrics)
    result["checksum"] = checksum(result)
    write_json(udir / "result.json", result)


def test_the_section_on_the_fixtures(results_dir):
    res = load_results(results_dir)
    [section] = frameworks_sections(res)
    assert section.title == "Cross-framework agreement"
    tables = _tables(section)
    assert set(tables) == {"Claim metric per framework", "Verdict per framework", "Training curves of paired units",
                           "JAX against PyTorch speed per operation"}
    curves = tables["Training curves of paired units"].set_index(["claim", "model"])
    # every (claim, model) with a unit in both frameworks; the corrupt unit's seed is not paired
    both = {(u.claim, u.model) for u in res.usable() if u.framework == "jax"}
    assert set(curves.index) == both
    assert curves.loc[("dp_loss", "lnn"), "seeds"] == "2" and curves.loc[("dp_loss", "lnn"), "frameworks"] == "jax / torch"
    # the fixture's logs are noise apart (1e-2 on losses near 1): every start differs
    assert set(curves["start differs"]) == {"yes"}
    verdicts = tables["Verdict per framework"].set_index("claim")
    for cid, row in verdicts.iterrows():
        by_fw = res.verdicts[cid]["by_framework"]
        assert (row["jax"], row["torch"]) == (by_fw["jax"], by_fw["torch"])
        assert row["same"] == ("yes" if by_fw["jax"] == by_fw["torch"] else "no")
    assert "non-finite seeds" in tables["Claim metric per framework"].columns


def test_the_built_report_has_the_section_once(built):
    md = built["markdown"].read_text()
    assert md.count("## Cross-framework agreement") == 1
    assert len(re.findall(r": Claim metric per framework( \(part 1 of \d\))?\*\*", md)) == 1
    assert ": Training curves of paired units" in md


@pytest.fixture
def edited(results_dir, tmp_path) -> Results:
    """A copy of the fixtures with: dp_loss/lnn torch logs = JAX's up to rounding until step 50, 5 % off
    after; rel_coords/lnn torch's first loss 1 % off; hnn_energy/hnn torch seed 0 diverged (inf)."""
    root = tmp_path / "results"
    shutil.copytree(results_dir, root)
    for seed in (0, 1):
        log = pd.read_csv(_unit(root, "dp_loss", "jax", "lnn", seed) / "train_log.csv")
        log["loss"] *= [1 + 1e-7 if s < 50 else 1.05 for s in log["step"]]
        _rewrite(_unit(root, "dp_loss", "torch", "lnn", seed), log)
        log = pd.read_csv(_unit(root, "rel_coords", "jax", "lnn", seed) / "train_log.csv")
        log.loc[0, "loss"] *= 1.01
        _rewrite(_unit(root, "rel_coords", "torch", "lnn", seed), log)
    _rewrite(_unit(root, "hnn_energy", "torch", "hnn", 0), energy_err_max=math.inf)
    return load_results(root)


def test_paired_curves_part_where_they_were_made_to(edited):
    curves = training_curves_table(edited).set_index(["claim", "model"])
    dp = curves.loc[("dp_loss", "lnn")]
    assert dp["start differs"] == "no" and dp["parted at step"] == "50, 50"
    assert float(dp["first loss rel. diff (max)"]) < START_TOL and float(dp["last loss rel. diff (max)"]) > PART
    rel = curves.loc[("rel_coords", "lnn")]
    assert rel["start differs"] == "yes" and rel["parted at step"] == "never, never"
    assert float(rel["first loss rel. diff (max)"]) == pytest.approx(0.01 / 1.01, rel=1e-3)


def test_a_diverged_seed_in_one_framework_is_flagged(edited):
    [section] = frameworks_sections(edited)
    table = _tables(section)["Claim metric per framework"].set_index(["claim", "model"])
    row = table.loc[("hnn_energy", "hnn")]
    assert row["non-finite seeds"] == "jax 0, torch 1" and row["seeds in both"] == "2"
    assert table.loc[("dp_loss", "lnn"), "non-finite seeds"] == "none"
    [bullets] = [b for b in section.blocks if isinstance(b, Bullets)]
    hits = [b for b in bullets.items if b.startswith("hnn_energy / hnn ")]
    assert len(hits) == 1 and "non-finite seeds differ (jax 0, torch 1)" in hits[0]
    # every row the table flags beyond the spread is listed too
    beyond = {f"{c} / {m} " for (c, m), r in table.iterrows() if r["beyond spread"] == "yes"}
    assert all(any(b.startswith(x) for b in bullets.items) for x in beyond)


def test_what_a_claim_metric_row_flags():
    row = {"claim": "c", "model": "m", "metric": "x", "rel. diff of means": "0.1", "beyond spread": "no",
           "max per-seed abs. diff": "0.5", "seed spread (std)": "1", "non-finite seeds": "none"}
    assert _flag(row) == ""
    assert "beyond the seed spread" in _flag({**row, "beyond spread": "yes"})
    assert "a paired seed differs by 2, more than the seed spread 1" in _flag({**row, "max per-seed abs. diff": "2"})
    assert _flag({**row, "max per-seed abs. diff": "not run", "seed spread (std)": "not run"}) == ""
    assert "non-finite seeds differ" in _flag({**row, "non-finite seeds": "jax 1, torch 0"})
    assert _flag({**row, "non-finite seeds": "jax 1, torch 1"}) == ""


def test_curve_agreement_needs_the_curves_to_stay_apart():
    a = pd.DataFrame({"step": [0, 10, 20, 30, 40], "loss": [1.0, 1.0, 1.0, 1.0, 1.0]})
    b = a.assign(loss=[1.0, 1.1, 1.0, 1.1, 1.1])         # apart at 10, together at 20, apart from 30
    assert curve_agreement(a, b) == {"start": 0.0, "parted_at": 30, "end": pytest.approx(0.1 / 1.1),
                                     "steps": 40, "n": 5}
    assert curve_agreement(a, a)["parted_at"] is None
    assert curve_agreement(a, b.assign(step=b["step"] + 5)) is None            # no common step
    assert curve_agreement(a, None) is None
    c = a.assign(loss=[1.0, 1.0, math.nan, math.inf, math.inf])               # NaN and a blow-up in one
    assert curve_agreement(a, c)["parted_at"] == 20


def test_verdicts_differing_between_frameworks():
    res = Results(root=Path("."), run={"frameworks": ["jax", "torch"]},
                  claims=[{"id": "a"}, {"id": "b"}, {"id": "c"}],
                  verdicts={"a": {"by_framework": {"jax": "reproduced", "torch": "partly"}},
                            "b": {"by_framework": {"jax": "reproduced", "torch": "reproduced"}},
                            "c": {"by_framework": {"jax": "reproduced"}}})
    df = verdicts_table(res).set_index("claim")
    assert list(df.index) == ["a", "b"]
    assert df.loc["a", "same"] == "no" and df.loc["b", "same"] == "yes"


def test_one_framework_has_no_comparison(results_dir, tmp_path):
    root = tmp_path / "results"
    shutil.copytree(results_dir, root)
    for claim_dir in (root / "units").iterdir():
        shutil.rmtree(claim_dir / "torch", ignore_errors=True)
    run = json.loads((root / "run.json").read_text())
    write_json(root / "run.json", {**run, "frameworks": ["jax"]})
    res = load_results(root)
    assert training_curves_table(res) is None and verdicts_table(res) is None
    [section] = frameworks_sections(res)
    assert "Comparison across frameworks: not run (frameworks found: jax)" in section.blocks[0].text
    assert CORRUPT[1] == "torch"   # (the corrupt fixture unit went with the torch folders)
