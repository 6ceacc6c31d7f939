"""`lagbench table` and the report's "Results by system" (`reports.systems_table`): every model per system,
over its seeds, beside the predictors scored into the same folder."""
import re
import shutil

import numpy as np
import pandas as pd

from lagbench.cli import main
from lagbench.replication.predictor.score import score
from lagbench.reports.systems_table import shown, systems_table


def test_one_row_per_claim_model_and_framework_with_its_seeds_spread(results_dir, tmp_path, capsys):
    root = tmp_path / "r"
    shutil.copytree(results_dir, root)
    score(lambda q, qd: np.zeros_like(q), "double_pendulum", "smoke", out=root, label="zero")
    df = systems_table(root)
    claims = df[df["source"] == "claim"]
    assert set(claims["system"]) == {"double_pendulum"}   # every fixture unit records the double pendulum's protocol
    row = claims[(claims["claim"] == "dp_loss") & (claims["model"] == "lnn") & (claims["framework"] == "jax")].iloc[0]
    assert row["seeds"] == 2 and row["heldout_l1_min"] <= row["heldout_l1"] <= row["heldout_l1_max"]
    assert row["heldout_l1_min"] < row["heldout_l1_max"]   # two seeds, two values
    zero = df[df["source"] == "predictor"].iloc[0]
    assert zero["model"] == "zero" and zero["heldout_l1"] >= zero["null_heldout_l1"] and zero["vpt_s"] >= 0
    assert "[" in shown(claims)["heldout_l1"].iloc[0]
    assert main(["table", "--results", str(root), "--system", "double_pendulum"]) == 0
    out = capsys.readouterr().out
    assert "double_pendulum" in out and "zero" in out
    assert len(pd.read_csv(root / "summary" / "systems.csv")) == len(df)
    assert main(["table", "--results", str(root), "--system", "wave"]) == 2
    assert "no model of wave" in capsys.readouterr().err


def test_the_report_has_the_table(built):
    text = built["markdown"].read_text()
    assert "## Results by system" in text and re.search(r"\*\*Table \d+: double_pendulum( \(part 1 of \d\))?\*\*", text)


def test_the_table_names_what_it_leaves_out_in_the_reports_words(small_results_dir, tmp_path, capsys):
    """Issue 85, item 5: a unit whose checksum fails is flagged by `lagbench table` as the report flags it."""
    import json

    from lagbench.reports.load import load_results
    from lagbench.reports.tables import excluded_note, problem_units_table

    root = tmp_path / "r"
    shutil.copytree(small_results_dir, root)
    unit = sorted(root.glob("units/*/*/*/seed*/result.json"))[0]
    d = json.loads(unit.read_text())
    d["metrics"]["heldout_l1"] = 1e-9   # a better number than was computed: the checksum no longer matches
    unit.write_text(json.dumps(d))
    score(lambda q, qd: np.zeros_like(q), "double_pendulum", "smoke", out=root, label="zero")
    record = root / "predict" / "double_pendulum" / "zero" / "result.json"
    record.write_text(record.read_text().replace('"zero"', '"zeros"', 1))
    assert main(["table", "--results", str(root)]) == 0
    err = capsys.readouterr().err
    rel = unit.parent.relative_to(root).as_posix()
    assert excluded_note("table") in err and rel in err and "checksum mismatch" in err, err
    assert problem_units_table(load_results(root)).to_string(index=False) in err   # the report's table, as is
    assert "predict/double_pendulum/zero: " in err and "; not used" in err, err
    assert excluded_note("report") == excluded_note("table").replace("this table", "this report")
