"""The README's claims table is the output of `reports.readme_table` on the committed sample report of the
verdict-of-record run (`docs/sample_report/`), never typed by hand; the sample's verdicts agree with its own
report."""
import json
from pathlib import Path

from markdown_tables import claim_rows

from lagbench.reports import readme_table

ROOT = Path(__file__).resolve().parents[2]
SAMPLE = ROOT / "docs" / "sample_report"


def test_readme_table_is_the_generated_one():
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    assert readme_table.BEGIN in text and readme_table.END in text, "the README lost the claims table's markers"
    a = text.index(readme_table.BEGIN)
    b = text.index(readme_table.END) + len(readme_table.END)
    assert text[a:b] == readme_table.block(SAMPLE), ("the README's claims table differs from the sample run's; "
                                                      "regenerate it: python -m lagbench.reports.readme_table docs/sample_report")


def test_the_sample_is_a_test_split_run_and_its_report_shows_the_same_verdicts():
    verdicts = json.loads((SAMPLE / "verdicts.json").read_text())
    assert verdicts["split"] == "test"
    report = (SAMPLE / "REPORT.md").read_text(encoding="utf-8")
    rows = {}
    for title in ("Scorecard", "Checks"):   # by their "claim" and "verdict" columns
        rows.update({cid: r["verdict"] for cid, r in claim_rows(report, title).items()})
    for c in verdicts["claims"]:
        assert rows[c["id"]].startswith(c["verdict"]), c["id"]


def test_table_lists_every_claim_with_its_verdict_and_variants():
    claims = [{"id": "a", "number": 1, "title": "A", "paper": "P", "section": "§1", "key": "m", "metric": "x",
               "kind": "claim", "published": {"m": {"value": 0.5, "kind": "held-out"}}},
              {"id": "b", "number": 2, "title": "B", "paper": "P", "section": "§2", "key": "n", "metric": "y",
               "kind": "check", "published": {}}]
    verdicts = {"profile": "quick", "split": "test", "claims": [
        {"id": "a", "verdict": "partly", "seeds": [1000, 1001],
         "parts": [{"name": "p1", "verdict": "reproduced"}, {"name": "p2", "verdict": "not reproduced"},
                   {"name": "s", "verdict": "reproduced", "check": True}],
         "values": {"jax": {"m": {"mean": 0.25}}, "torch": {"m": {"mean": 0.3}}},
         "variants": [{"name": "with gamma", "verdict": "reproduced"}]},
        {"id": "b", "verdict": "not run", "seeds": [1000]}]}
    out = readme_table.table(claims, verdicts)
    assert "test split; seeds from 1000: 2 a model (1 in claim 2)" in out
    assert "| 1 | A | P §1 | partly | p1: reproduced; p2: not reproduced | m x: JAX 0.25, PyTorch 0.3 | 0.5 (held-out) |" in out
    assert "| 2 (check) | B | P §2 | not run | – | not run | none |" in out
    assert 'claim 1, variant "with gamma": reproduced' in out
