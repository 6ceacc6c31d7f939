"""The built report: every claim row, "not run", corrupt exclusion, figures, PDF, no heavy imports."""

import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

from markdown_tables import claim_rows as rows_of
from markdown_tables import md_table
from result_fixtures import CLAIMS, CORRUPT, NOT_RUN_CLAIM, write_json

from lagbench.reports import build_report
from lagbench.reports.pdf import page_count

# the report recomputes verdicts with replication.claims.verdicts and the claim records (pure NumPy/pandas);
# it never loads a framework, the systems or models, or the training and evaluation code
HEAVY = ["jax", "torch", "equinox", "optax", "diffrax", "systems", "models", "lagbench.replication.training.train",
         "lagbench.replication.training.train_jax", "lagbench.replication.training.train_torch", "lagbench.replication.evaluation.routines", "lagbench.replication.run.units",
         "lagbench.replication.run.runner", "lagbench.replication.training.data"]


def claim_rows(md: str) -> dict[str, dict]:
    """The scorecard's and the checks' rows by claim: #, claim, verdict, why, key number, published, flags."""
    return {**rows_of(md, "Scorecard"), **rows_of(md, "Checks")}


def test_markdown_has_every_claim_row_and_not_run(built):
    md = built["markdown"].read_text()
    rows = claim_rows(md)
    assert set(rows) == {c[0] for c in CLAIMS}
    assert all(rows[NOT_RUN_CLAIM][c] == "not run" for c in ("verdict", "why", "key number"))
    # recomputed from the unit files: dp_loss's models pass their bar (null recorded) and agree;
    # dp_energy's rollouts record no divergence count, so its LNN cannot pass its rollout bar
    assert rows["dp_loss"]["verdict"] == "reproduced; 1 corrupt unit excluded"
    assert rows["dp_energy"]["verdict"] == "inconclusive"
    assert "Claims: published against reproduced" not in md   # folded into the scorecard
    assert "summary/verdicts.json disagrees with the unit files for" in md
    for line in md.splitlines():
        if line.startswith("|"):
            cells = re.split(r"(?<!\\)\|", line.strip())[1:-1]
            assert all(c.strip() for c in cells), line
    for section in ("Double pendulum", "Relativistic", "Wave equation", "DeLaN", "Initialisation",
                    "Speed against error", "Cross-framework agreement", "Findings", "Environment"):
        assert f"## {section}" in md


def test_corrupt_unit_is_listed_and_excluded(built):
    md = built["markdown"].read_text()
    rel = "units/{}/{}/{}/seed{}".format(*CORRUPT)
    assert f"| {rel} | corrupt | result.json checksum mismatch |" in md
    assert not re.search(r"(?<![\d.])999(\.0*)?(?![\d.e])", md)   # the corrupt value, not a digit run of another
    key = claim_rows(md)["dp_loss"]["key number"]   # the corrupt third seed is not among the seeds counted
    assert key.startswith("lnn heldout_l1") and re.search(r"PyTorch \S+ \(\S+ to \S+, 2 seeds\)$", key), key


def test_figures_written_and_referenced(built):
    figs = built["figures"]
    names = {p.name for p in figs}
    for name in ("dp_energy_energy.png", "dp_energy_trajectory.png", "wave_lgn_spacetime.png",
                 "delan_arm_decomposition.png", "delan_arm_torques.png", "delan_arm_data_efficiency.png", "init_study_training.png",
                 "dp_loss_speed_error.png", "bench_inference.png", "bench_scaling.png"):
        assert name in names
    md = built["markdown"].read_text()
    typ = built["typst"].read_text() + (built["pdf"].parent / "APPENDIX.typ").read_text()   # the two PDFs
    for p in figs:
        assert p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
        assert f"(figures/{p.name})" in md and f'"figures/{p.name}"' in typ
    assert not any("activation_study" in n for n in names)


def test_pdf_opens_with_expected_pages_and_text(built):
    pdf = built["pdf"]
    data = pdf.read_bytes()
    assert data.startswith(b"%PDF-") and data.rstrip().endswith(b"%%EOF")
    # the body flows on; each of the appendix's level-1 sections starts a page after it
    typ = built["typst"].read_text()
    appendix = typ[typ.index('#set heading(numbering: "A.1")'):]
    assert page_count(pdf) >= appendix.count("#heading(level: 1,") + 1 > 3
    assert b"/FontFile" in data and data.count(b"/Subtype /Image") + data.count(b"/Subtype/Image") >= len(
        built["figures"])
    typ = built["typst"].read_text()
    for cid, *_ in CLAIMS:
        assert f'"{cid}"' in typ


def test_claims_only_reads_not_run_everywhere(tmp_path):
    from result_fixtures import claim_record

    res = tmp_path / "res"
    write_json(res / "claims.json", {"schema": 1, "claims": [claim_record(c) for c in CLAIMS]})
    paths = build_report(res, tmp_path / "out", pdf=False)
    rows = claim_rows(paths["markdown"].read_text())
    assert set(rows) == {c[0] for c in CLAIMS}
    assert all(r["verdict"] == "not run" for r in rows.values())
    assert paths["figures"] == []


def test_empty_results_dir_says_nothing_was_run(tmp_path):
    paths = build_report(tmp_path / "empty", tmp_path / "out")
    md = paths["markdown"].read_text()
    assert "Nothing was run" in md
    assert paths["pdf"].read_bytes().startswith(b"%PDF-") and page_count(paths["pdf"]) > 1


def test_report_imports_no_training_code(results_dir, tmp_path):
    small = tmp_path / "res"
    for name in ("run.json", "claims.json"):
        small.mkdir(exist_ok=True)
        shutil.copy(results_dir / name, small / name)
    shutil.copytree(results_dir / "units" / "dp_energy", small / "units" / "dp_energy")
    code = (
        "import sys, json, reports\n"
        f"p = reports.build_report({str(small)!r}, {str(tmp_path / 'out')!r})\n"
        f"print(json.dumps([m for m in {HEAVY!r} if any(k == m or k.startswith(m + '.') for k in sys.modules)]))\n"
        "print(len(p['figures']))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                         cwd=Path(__file__).parents[2])
    loaded, nfig = out.stdout.strip().splitlines()[-2:]
    assert json.loads(loaded) == []
    assert int(nfig) >= 3
    assert re.search(r"%PDF-", (tmp_path / "out" / "REPORT.pdf").read_bytes()[:8].decode())


def scorecard_rows(md: str) -> dict[str, dict]:
    return rows_of(md, "Scorecard")


def test_report_opens_with_a_scorecard_of_recomputed_verdicts(built):
    md = built["markdown"].read_text()
    assert md.index("## Scorecard") < md.index("## Summary")
    rows = scorecard_rows(md)
    checks = rows_of(md, "Checks")
    assert set(rows) | set(checks) == {c[0] for c in CLAIMS} and not set(rows) & set(checks)
    assert "appendix_b" in checks and "dp_loss" in rows      # a check is kept apart from the paper claims
    assert re.search(r"Paper claims: (\d+ [a-z ]+, )*\d+ reproduced", md) and "Checks (implementation and numerics): " in md
    assert rows["dp_loss"]["verdict"].startswith("reproduced") and rows["dp_energy"]["verdict"] == "inconclusive"
    assert rows["dp_loss"]["claim"] == "dp_loss: claim dp_loss (LNN §5)"   # what it says and where in the paper
    # the key number: seed mean (lowest to highest seed, n seeds) per framework, with its unit
    assert re.fullmatch(r"lnn heldout_l1 \(units of q̈\): JAX 0\.0\d+ \(0\.0\d+ to 0\.0\d+, 2 seeds\); "
                        r"PyTorch 0\.0\d+ \(0\.0\d+ to 0\.0\d+, 2 seeds\)", rows["dp_loss"]["key number"])
    # why: the reason's category, the model below its bar on how many seeds
    assert re.match(r"BELOW BAR \(.+\): lnn passed on 0/2 seeds", rows["dp_energy"]["why"]), rows["dp_energy"]["why"]
    assert "±" not in rows["dp_loss"]["key number"] and "(n=" not in md_table(md, "Scorecard").to_string()
    assert re.search(r"Profile \w+, \w+ split, JAX and PyTorch; commit ", md)   # the frameworks it was decided in
    parts = rows_of(md, "Parts of the paper claims")
    assert parts["dp_loss"]["part"] == "similar held-out loss" and parts["dp_loss"]["verdict"] == "reproduced"
    assert re.fullmatch(r"\S+ \[\S+, \S+\]", parts["dp_loss"]["JAX"])   # JAX: point [low, high]
    full = rows_of(md, "Reasons in full (parts not reproduced)")
    assert "below the competence bar" in full["dp_energy"]["reason"]


def test_deleted_units_change_the_verdict_and_an_unfinished_run_says_so(small_results_dir, tmp_path):
    res = tmp_path / "res"
    shutil.copytree(small_results_dir, res)
    run = json.loads((res / "run.json").read_text())
    run["finished"] = None
    run["planned_units"] = [f"dp_loss/{fw}/{m}/seed{k}" for fw in ("jax", "torch") for m in ("lnn", "baseline")
                            for k in (0, 1)]
    write_json(res / "run.json", run)
    shutil.rmtree(res / "units" / "dp_loss" / "jax" / "baseline")
    shutil.rmtree(res / "units" / "dp_loss" / "torch" / "baseline")
    md = build_report(res, tmp_path / "out", pdf=False)["markdown"].read_text()
    assert scorecard_rows(md)["dp_loss"]["verdict"].startswith("not run")   # the stored verdict said "reproduced"
    assert "This run is unfinished: 4 planned unit(s) have no result" in md
    assert "| units/dp_loss/jax/baseline/seed0 | missing |" in md
    assert "No failed, corrupt or missing units" not in md


def test_cross_framework_table_flags_a_difference_beyond_the_seed_spread(results_dir):
    from lagbench.reports.compare import cross_framework_table
    from lagbench.reports.load import load_results

    df = cross_framework_table(load_results(results_dir)).set_index(["claim", "model"])
    row = df.loc[("dp_loss", "baseline")]
    assert row["seed spread (std)"] != "not run" and row["beyond spread"] in ("yes", "no")
    # the flag follows the numbers shown (means and spread, as printed)
    flags = df["beyond spread"][df["beyond spread"] != "not run"]
    for (claim, model), flag in flags.items():
        r = df.loc[(claim, model)]
        gap = abs(float(r["jax"]) - float(r["torch"]))
        assert (flag == "yes") == (gap > float(r["seed spread (std)"])), (claim, model)


def test_the_metric_dumps_sit_in_an_appendix_and_shared_trainings_are_drawn_once(results_dir, tmp_path):
    from lagbench.reports.build import build_sections
    from lagbench.reports.load import load_results
    from lagbench.reports.sections_claims import claim_section

    sections = build_sections(results_dir, tmp_path / "a")
    titles = [s.title for s in sections]
    dumps = [s.title for s in sections for b in s.blocks if "all recorded metrics" in getattr(b, "title", "")]
    assert dumps and set(dumps) == {"Appendix: all recorded metrics"}
    assert titles.index("Appendix: all recorded metrics") > titles.index("Environment")
    res = load_results(results_dir)
    claim = next(c for c in res.claims if c["id"] == "dp_loss")
    drawn = {}
    first = claim_section(res, claim, tmp_path / "c", drawn)
    again = claim_section(res, claim, tmp_path / "c", drawn)   # the same trainings a second time
    assert any("train" in getattr(b, "path", "") for b in first.blocks)   # its training figure
    assert any("the same trainings as dp_loss's" in getattr(b, "text", "") for b in again.blocks)


# the long dumps: REPORT.md keeps them, REPORT.pdf names where they are, APPENDIX.pdf holds them
LONG_DUMPS = ("Claim details", "Speed against error per unit", "Velocity-Hessian health (LNN and LGN)",
              "Results by system", "Appendix: all recorded metrics", "Appendix: index of tables and figures")


def test_the_long_dumps_leave_the_main_pdf_for_the_appendix_pdf_and_the_markdown_keeps_every_section(built, results_dir, tmp_path):
    from lagbench.reports.build import body_and_appendix
    from lagbench.reports.pdf import lit

    md = built["markdown"].read_text()
    main = built["typst"].read_text()
    second = (built["pdf"].parent / "APPENDIX.typ").read_text()
    assert built["appendix_pdf"].read_bytes().startswith(b"%PDF-") and page_count(built["appendix_pdf"]) > 1
    headings = lambda typ: set(re.findall(r'^#heading\(level: \d, "(.*)"\)$', typ, re.M))  # noqa: E731
    for title in LONG_DUMPS:
        assert title not in headings(main) and title in headings(second), title
        assert f"## {title}\n" in md, title
    assert "APPENDIX.pdf" in main and "Results by system" in main[main.index("APPENDIX.pdf"):]
    body, appendix = body_and_appendix(results_dir, tmp_path)
    for s in body + appendix:   # REPORT.md: every section; the two PDFs: each section once, in one of them
        assert f"{'#' * (s.level + 1)} {s.title}\n" in md, s.title
        assert (lit(s.title)[1:-1] in headings(main)) != (lit(s.title)[1:-1] in headings(second)), s.title
    assert not {t for t in headings(main) if any(t.startswith(d) for d in ("Claim details", "Appendix: all"))}
