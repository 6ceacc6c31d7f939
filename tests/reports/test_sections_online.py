"""Learning online on the four-joint arm (`lagbench online --system four_joint_arm`, `reports.sections_online`): a
tiny real run writes OUT/online_four_joint_arm/ only, with learners of 4 joints and the arm's gains; its summary
reaches the report as its own section; the learners default to the two-link arm's; a bad --system is one line."""
import json

import numpy as np
import pandas as pd
import pytest

from lagbench.cli import main
from lagbench.replication.studies import online as O
from lagbench.replication.studies.online_learner import claim_model, learner


@pytest.fixture(scope="module")
def tiny_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("online4")
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(O, "one_thread", lambda: {"test": "threads left as they are"})
        assert main(["online", "--system", "four_joint_arm", "--out", str(out), "--seconds", "0.2", "--window", "0.1",
                     "--models", "delan,ff", "--frameworks", "jax", "--unseen-refs", "0", "--sustain", "0.2",
                     "--quiet"]) == 0
    return out


def test_a_tiny_run_learns_on_the_four_joint_arm_into_its_own_folder(tiny_run):
    assert [p.name for p in tiny_run.iterdir()] == ["online_four_joint_arm"]
    folder = tiny_run / "online_four_joint_arm"
    c, s = pd.read_csv(folder / "curves.csv"), pd.read_csv(folder / "summary.csv")
    assert list(c.columns) == O.CURVE_COLUMNS and list(s.columns) == O.SUMMARY_COLUMNS
    assert list(s["controller"]) == ["pd", "exact", "delan", "ff"] and len(c) == 4 * 2
    assert (s.loc[s["controller"].isin(["delan", "ff"]), "steps"] == 100).all()
    assert (s["n_diverged_ticks"] == 0).all() and s["final_window_mse"].notna().all()
    assert (s.loc[s["controller"] == "exact", "final_ratio_to_pd"] < 1e-2).all()
    setup = json.loads((folder / "setup.json").read_text())
    assert setup["system"] == "four_joint_arm" and setup["kp"] == [20.0] * 4


def test_the_learners_follow_the_arm_and_default_to_the_two_link_arm():
    q = np.zeros(4)
    for kind in ("delan", "ff"):
        assert learner(kind, "jax", 0, hidden=(8, 8), dof=4).tau(q, q, q).shape == (4,)
    spec2, spec4 = claim_model("ff")[0], claim_model("ff", dof=4)[0]
    assert (spec2.dof, spec2.extra_inputs, spec4.dof, spec4.extra_inputs) == (2, 2, 4, 4)


def test_the_summary_reaches_the_report_as_its_own_section(tiny_run, tmp_path):
    from lagbench.reports.document import Table
    from lagbench.reports.load import load_results
    from lagbench.reports.sections_online import online_sections

    (section,) = online_sections(load_results(tiny_run), tmp_path)
    assert section.title == "Learning online while tracking the four-joint arm (study)"
    (table,) = [b for b in section.blocks if isinstance(b, Table)]
    s = pd.read_csv(tiny_run / "online_four_joint_arm" / "summary.csv")
    assert table.sources == ["online_four_joint_arm/summary.csv"] and len(table.df) == len(s)
    assert list(table.df["controller"][:2]) == ["PD alone", "true inverse dynamics"]
    assert table.df.loc[0, "reaches the bar, held (s)"] == "never"   # PD alone is never 10x below itself
    assert table.df.loc[1, "reaches the bar, held (s)"] == table.df.loc[1, "first at the bar (s)"] == "0.1"
    assert table.df.loc[2, "compute per tick, mean / p99 (µs)"] != "-"
    text = " ".join(getattr(b, "text", "") for b in section.blocks)
    assert "0.2 s of simulated time" in text and "reached when held 0.2 s" in text
    assert online_sections(load_results(tmp_path), tmp_path) == []   # no study: no section


def test_a_bad_system_is_one_line(tmp_path, capsys):
    assert main(["online", "--system", "three_link_arm", "--out", str(tmp_path / "o"), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--system" in err and not (tmp_path / "o").exists()


def test_a_summary_without_the_first_crossing_shows_its_t_reach_as_the_first_crossing(tmp_path):
    from lagbench.reports.document import Table
    from lagbench.reports.load import load_results
    from lagbench.reports.sections_online import FOLDER, online_sections

    (tmp_path / FOLDER).mkdir()
    pd.DataFrame([{"controller": "ff", "framework": "jax", "seed": 0, "t_reach_s": 0.5, "t_settle_s": 9.0,
                   "final_window_mse": 1e-4, "final_ratio_to_pd": 3e-4, "unseen_ratio_to_pd": 0.1,
                   "compute_us_mean": 1000.0, "compute_us_p99": 2000.0, "fits_period_mean": True,
                   "fits_period_p99": False}]).to_csv(tmp_path / FOLDER / "summary.csv", index=False)
    (section,) = online_sections(load_results(tmp_path), tmp_path)
    (table,) = [b for b in section.blocks if isinstance(b, Table)]
    assert table.df.loc[0, "first at the bar (s)"] == "0.5" and table.df.loc[0, "reaches the bar, held (s)"] == "-"
