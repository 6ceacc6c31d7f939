"""Reports sized to what ran (issue 86, item 5): a report and the run's console summary name only the claims the
run asked for (run.json's "claims"); a fit's report is titled as one and speaks of no profile; `lagbench table`
shows the profile and never puts rows of two profiles in one table; counts print as integers, and an energy
error beyond the data's own scale as "diverged"."""
import json
import shutil

import numpy as np
import pandas as pd
from result_fixtures import CLAIMS, checksum, claim_record, write_unit

from lagbench.cli import main
from lagbench.reports.build import FIT_TITLE, TITLE, titled
from lagbench.reports.fmt import count, num
from lagbench.reports.load import load_results
from lagbench.reports.markdown import render_markdown
from lagbench.reports.systems_table import by_table, mixed, shown, systems_table

ASKED = ["dp_energy", "dp_loss"]
OTHERS = sorted(c[0] for c in CLAIMS if c[0] not in ASKED)


def _two_claim_run(small_results_dir, root, asked=ASKED):
    """The two-claim fixture as `lagbench run --claims dp_loss,dp_energy` leaves it: claims.json catalogues
    every claim, run.json records the claims asked for."""
    shutil.copytree(small_results_dir, root)
    (root / "claims.json").write_text(json.dumps({"schema": 1, "claims": [claim_record(c) for c in CLAIMS]}))
    run = json.loads((root / "run.json").read_text())
    if asked is not None:
        run["claims"] = asked
    (root / "run.json").write_text(json.dumps(run))
    return root


def test_a_two_claim_runs_report_lists_two_claims(small_results_dir, tmp_path):
    root = _two_claim_run(small_results_dir, tmp_path / "r")
    assert sorted(c["id"] for c in load_results(root).claims) == ASKED
    title, body, appendix = titled(root, tmp_path / "rep")
    text = render_markdown(title, body + appendix)
    assert title == TITLE and all(cid in text for cid in ASKED)
    assert not [cid for cid in OTHERS if cid in text], [cid for cid in OTHERS if cid in text]
    old = _two_claim_run(small_results_dir, tmp_path / "old", asked=None)   # a run.json that records no claims
    assert sorted(c["id"] for c in load_results(old).claims) == sorted(c[0] for c in CLAIMS)


def test_an_earlier_invocations_claims_stay_in_the_report(small_results_dir, tmp_path):
    root = _two_claim_run(small_results_dir, tmp_path / "r", asked=["dp_energy"])
    (root / "runs").mkdir()
    (root / "runs" / "run-20261121T080000Z.json").write_text(json.dumps({"claims": ["dp_loss", "wave_lgn"]}))
    assert sorted(c["id"] for c in load_results(root).claims) == ["dp_energy", "dp_loss", "wave_lgn"]


def test_the_run_summary_on_the_console_lists_the_claims_asked_for(tmp_path, monkeypatch, capsys):
    from lagbench.replication.run import runner

    def run(out, **_):
        (tmp_path / "o").mkdir()
        (tmp_path / "o" / "run.json").write_text(json.dumps({"claims": ["dp_loss"]}))
        return {"claims": [{"id": c[0], "verdict": "not run", "reason": "-"} for c in CLAIMS], "errors": []}

    monkeypatch.setattr(runner, "run", run)
    assert main(["run", "--profile", "smoke", "--out", str(tmp_path / "o")]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert [ln.split()[0] for ln in lines] == ["dp_loss"], lines


def test_a_fits_report_is_titled_as_a_fit_and_names_no_profile(tmp_path):
    root = tmp_path / "fit"
    write_unit(root, "fit", "jax", "lnn", 0, np.random.default_rng(0))
    title, body, appendix = titled(root, tmp_path / "rep")
    text = render_markdown(title, body + appendix)
    assert title == FIT_TITLE and text.startswith("# Fit report") and "Replication report" not in text
    assert "| profile |" not in text and "Run manifest" not in text, text


def _quick(root, claim):
    """The claim's units of the fixture re-recorded as made under the quick profile (checksums renewed)."""
    for path in root.glob(f"units/{claim}/*/*/seed*/result.json"):
        r = json.loads(path.read_text())
        r["profile"] = "quick"
        r["checksum"] = checksum(r)
        path.write_text(json.dumps(r))


def test_the_table_shows_the_profile_and_tables_two_profiles_apart(small_results_dir, tmp_path, capsys):
    root = tmp_path / "r"
    shutil.copytree(small_results_dir, root)
    df = systems_table(root)
    assert set(df["profile"]) == {"smoke"} and not mixed(df) and [t for t, _ in by_table(df)] == ["double_pendulum"]
    assert set(shown(df)["profile"]) == {"smoke"}
    _quick(root, "dp_energy")
    df = systems_table(root)
    tables = dict(by_table(df))
    assert sorted(tables) == ["double_pendulum, profile quick", "double_pendulum, profile smoke"]
    assert set(tables["double_pendulum, profile quick"]["claim"]) == {"dp_energy"}
    assert main(["table", "--results", str(root)]) == 0
    out, err = capsys.readouterr()
    assert "double_pendulum, profile quick\n" in out and "double_pendulum, profile smoke\n" in out
    assert "rows of profiles quick and smoke are in separate tables" in err, err
    assert set(pd.read_csv(root / "summary" / "systems.csv")["profile"]) == {"quick", "smoke"}


def test_counts_print_as_integers():
    assert num(70311) == "70311" and num(np.int64(1150)) == "1150" and num(1150.5) == "1150"
    assert count(1150.0) == "1,150" and count(float("nan"), "–") == "–"
    df = pd.DataFrame([{"system": "pendulum", "profile": "smoke", "source": "claim", "claim": "c", "model": "lnn",
                        "framework": "jax", "status": "ok", "seeds": 3, "params": 1150.0, "train_samples": 123456.0,
                        "train_time_s": 2.0, **{m: np.nan for m in ("heldout_l1", "heldout_l1_min", "heldout_l1_max")}}])
    from lagbench.reports import systems_table as st

    df = df.assign(**{m + k: np.nan for m in st.METRICS for k in ("", "_min", "_max")})
    row = shown(df).iloc[0]
    assert (row["params"], row["train samples"], row["seeds"]) == ("1,150", "123,456", "3")
    blown = shown(df.assign(energy_err_final=1.05e50, energy_err_final_min=0.2, energy_err_final_max=1e59)).iloc[0]
    assert blown["energy_err_final"] == "diverged [0.2, diverged]"   # beyond the data's scale: never a number
