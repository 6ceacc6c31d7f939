"""`lagbench run --profile smoke`: every claim end to end, with valid result files (the session's run: some
claims in one framework, `tests/replication/conftest.py`; `tox -e slow` runs every claim in both)."""
import json

import pandas as pd
import pytest

from lagbench.files import results as R
from lagbench.replication.claims import CLAIMS, VERDICTS
from lagbench.replication.run.runner import run


def _every_claim_has_a_verdict(summary, frameworks_of):
    by_id = {c["id"]: c for c in summary["claims"]}
    assert set(by_id) == set(CLAIMS)
    for cid, c in by_id.items():
        assert c["verdict"] in VERDICTS and c["verdict"] != "not run", (cid, c)
        assert set(c["by_framework"]) == frameworks_of(cid), cid


def test_every_claim_gets_a_verdict_in_its_frameworks(smoke_results, smoke_frameworks):
    _every_claim_has_a_verdict(smoke_results[1], smoke_frameworks)
    assert {"jax", "torch"} == {fw for cid in CLAIMS for fw in smoke_frameworks(cid)}


@pytest.mark.slow   # slow: every claim compiled and trained twice (about 4 minutes on 2 cores)
def test_every_claim_gets_a_verdict_in_both_frameworks(tmp_path):
    _every_claim_has_a_verdict(run(profile="smoke", out=tmp_path, progress=False), lambda cid: {"jax", "torch"})


def test_result_files_verify_and_load_into_pandas(smoke_results):
    out, _ = smoke_results
    folders = sorted(p.parent for p in out.glob("units/*/*/*/seed*/result.json"))
    assert folders
    for f in folders:
        d = R.load_result(f)
        assert d["framework"] in ("jax", "torch") and d["metrics"]
        for name in d["files"]:
            if name.endswith(".csv"):
                assert len(pd.read_csv(f / name)) > 0, f / name
    units = pd.read_csv(out / "summary" / "units.csv")
    assert set(units["claim"]) == set(CLAIMS)
    assert json.loads((out / "claims.json").read_text())["claims"]


def test_frameworks_agree_on_the_exact_lagrangian(smoke_results):
    out, _ = smoke_results
    units = pd.read_csv(out / "summary" / "units.csv")
    ab = units[units["claim"] == "appendix_b"]
    assert len(ab) == 4 and (ab["max_abs_err"] <= 1e-12).all()


def test_a_rerun_skips_finished_units(smoke_results, smoke_frameworks):
    out, _ = smoke_results
    before = {p: p.stat().st_mtime_ns for p in out.glob("units/*/*/*/seed*/result.json")}
    run(profile="smoke", out=out, claims=["dp_loss"], frameworks=tuple(sorted(smoke_frameworks("dp_loss"))),
        progress=False)
    after = {p: p.stat().st_mtime_ns for p in out.glob("units/*/*/*/seed*/result.json")}
    assert before == after


def test_report_builds_from_real_smoke_results(smoke_results, tmp_path):
    from lagbench import reports

    out, _ = smoke_results
    paths = reports.build_report(out, tmp_path)
    md = paths["markdown"].read_text()
    for cid in CLAIMS:
        assert cid in md
    health = md.split("\n## Velocity-Hessian health")[1].split("\n## ")[0]   # its section, its tables in any parts
    # logged in training, in both frameworks
    assert "| dp_loss | jax | lnn |" in health and "| activation_study | torch | lnn_act-" in health
    assert paths["pdf"].read_bytes()[:4] == b"%PDF"
