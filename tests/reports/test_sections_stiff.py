"""The stiff-solver study's output reaches the report, with the picked solver marked."""
import json

from lagbench.replication.studies.stiff_solvers import stiff_study
from lagbench.reports.load import load_results
from lagbench.reports.sections_stiff import stiff_sections


def test_stiff_study_rows_reach_the_report(tmp_path):
    df = stiff_study(n_ics=2, t_end=1.0, cases=[("dopri8", 1e-10), ("tsit5", 1e-6)], verlet_dt=(1e-2,))
    assert list(df["solver"]) == ["dopri8", "tsit5", "verlet"]
    assert df.loc[df["solver"] == "dopri8", "picked"].item()               # the chooser's pick is in the table
    assert df.loc[df["solver"] == "dopri8", "state_err"].item() < 1e-6
    (tmp_path / "stiff").mkdir()
    df.to_csv(tmp_path / "stiff" / "solvers.csv", index=False)
    (tmp_path / "stiff" / "choice.json").write_text(json.dumps({"system": "stiff_chain", **df.attrs}))
    (section,) = stiff_sections(load_results(tmp_path))
    table = section.blocks[-1].df
    assert list(table.loc[table["picked"] == "picked", "solver"]) == ["dopri8"]


def test_missing_study_says_not_run(tmp_path):
    (section,) = stiff_sections(load_results(tmp_path))
    assert "Not run" in section.blocks[-1].text
