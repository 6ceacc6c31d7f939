"""The README's claims tables are the output of `reports.readme_table` on the committed runs their markers name
(the quick run's report folder `docs/quick_report/`; the store `runs/full/`, whose report is
`docs/sample_report/`), never typed by hand; each run's verdicts agree with its own report."""
from pathlib import Path

from markdown_tables import claim_rows

from lagbench.reports import readme_table

ROOT = Path(__file__).resolve().parents[2]
QUICK = "docs/quick_report"
# The report made from a store lives beside the docs; a report folder is its own.
REPORT_OF = {"runs/full": "docs/sample_report"}


def test_readme_table_is_the_generated_one():
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    found = readme_table.blocks(text)
    assert QUICK in [folder for folder, _ in found], "the README lost the claims table's markers"
    for folder, block in found:
        assert block == readme_table.block(folder, ROOT), (f"the README's claims table of {folder} differs from "
                                                           f"that run's; regenerate it: {readme_table.MAKE} {folder}")


def test_blocks_are_found_by_the_folder_their_marker_names():
    text = ("intro\n" + readme_table.begin("runs/full") + "\nA\n" + readme_table.END + "\nmiddle\n"
            + readme_table.begin("docs/sample_report") + "\nB\n" + readme_table.END + "\n")
    found = readme_table.blocks(text)
    assert [f for f, _ in found] == ["runs/full", "docs/sample_report"]
    assert found[0][1] == readme_table.begin("runs/full") + "\nA\n" + readme_table.END


def test_each_table_is_a_test_split_run_and_its_report_shows_the_same_verdicts():
    folders = [folder for folder, _ in readme_table.blocks((ROOT / "README.md").read_text(encoding="utf-8"))]
    assert QUICK in folders
    for folder in folders:
        _, verdicts = readme_table.read(ROOT / folder)
        assert verdicts["split"] == "test", folder
        report = (ROOT / REPORT_OF.get(folder, folder) / "REPORT.md").read_text(encoding="utf-8")
        rows = {}
        for title in ("Scorecard", "Checks"):   # by their "claim" and "verdict" columns
            rows.update({cid: r["verdict"] for cid, r in claim_rows(report, title).items()})
        for c in verdicts["claims"]:
            assert rows[c["id"]].startswith(c["verdict"]), (folder, c["id"])


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
