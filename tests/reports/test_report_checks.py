"""Issue 83, checked mechanically on the report built from the fixtures: every figure's caption names what it
shows, the paper figure it recreates (or none) and its source; no table is wider than the text; the glossary
defines every metric name the tables show; no table cell holds a raw Python record; a yes/no metric reads as
k/n seeds; tables and figures carry the same numbers in REPORT.md and the PDF, and the index lists them all."""
import json
import re

import pandas as pd
from markdown_tables import claim_rows, md_table, md_tables
from result_fixtures import POOLED, SEEDS

FIGURE = re.compile(r"^\*Figure (\d+): (.+)\*$", re.M)


def _both_typst(built) -> str:
    return built["typst"].read_text() + (built["typst"].parent / "APPENDIX.typ").read_text()


def test_every_figure_caption_names_what_it_shows_the_paper_figure_and_its_source(built):
    md = built["markdown"].read_text()
    captions = FIGURE.findall(md)
    assert len(captions) == len(built["figures"]) > 5
    assert [int(n) for n, _ in captions] == list(range(1, len(captions) + 1))   # numbered in reading order
    for n, text in captions:
        shows = re.search(r" Shows: (.+?)\. Paper figure: (.+?)\. Source: (.+)\.$", text)
        assert shows and all(len(g.strip()) > 3 for g in shows.groups()), (n, text)
        assert "units/" in shows[3] or "bench/" in shows[3] or "/" in shows[3], (n, text)
    typ = _both_typst(built)   # REPORT.typ and APPENDIX.typ: every number in one PDF or the other
    assert {int(n) for n in re.findall(r'"Figure (\d+): ', typ)} == {int(n) for n, _ in captions}
    assert "numbering: none" in typ   # typst's own numbering is off: the PDF prints the report's numbers


def _typst_tables(typ: str):
    """(font size pt, [column widths pt], [cell texts], inset pt) of every table in REPORT.typ."""
    lit = r'"((?:[^"\\]|\\.)*)"'
    for m in re.finditer(r"#text\(size: ([\d.]+)pt[^\[]*\)\[#table\(columns: \(([^)]*)\), inset: ([\d.]+)pt,"
                         r".*?\n  table\.header\((.*?)\),\n  (.*?)\)\]\n", typ, re.S):
        widths = [float(w.removesuffix("pt")) for w in m[2].split(",") if w.strip()]
        cells = re.findall(lit, m[4]) + re.findall(lit, m[5])
        yield float(m[1]), widths, cells, float(m[3])


def test_no_table_is_wider_than_the_text_nor_a_cell_wider_than_its_column(built):
    typ = built["typst"].read_text()
    page = re.search(r'#set page\(paper: "a4", margin: \(x: ([\d.]+)cm', typ)
    text_width = (21.0 - 2 * float(page[1])) / 2.54 * 72   # A4 is 21 cm wide; pt
    tables = list(_typst_tables(typ))
    assert len(tables) == typ.count("#table(") > 20
    for size, widths, cells, inset in tables:
        assert sum(widths) <= text_width + 0.5, (sum(widths), cells[:len(widths)])
        assert len(cells) % len(widths) == 0
        for i, c in enumerate(cells):   # the longest unbreakable run at half an em a glyph fits its column
            run = max(len(w) for w in re.split(r"[\s\u200b]+", c.replace("\\n", " ")))
            assert run * 0.5 * size + 2 * inset <= widths[i % len(widths)] + 0.01, (c, widths)
    md = built["markdown"].read_text()
    for title, df in md_tables(md).items():   # no header printed twice, no column with nothing in it
        assert len(df.columns) == len(set(df.columns)), title
        if len(df) and len(df.columns) > 1:
            empty = [c for c in df.columns[1:] if df[c].isin(["", "–", "-", "nan", "NaN"]).all()]
            assert not empty, (title, empty)


def _fixture_metric_names(results_dir) -> set[str]:
    names = {c["metric"] for c in json.loads((results_dir / "claims.json").read_text())["claims"]}
    for f in results_dir.glob("units/*/*/*/seed*/result.json"):
        names |= set(json.loads(f.read_text())["metrics"])
    for f in results_dir.glob("units/*/*/*/seed*/rollouts.csv"):
        names |= set(pd.read_csv(f).columns) - {"traj", "set"}
    return names


def test_the_glossary_defines_every_metric_name_the_tables_show(built, results_dir):
    md = built["markdown"].read_text()
    metrics = _fixture_metric_names(results_dir)
    tables = md_tables(md)
    # the body's metric names after the scorecard, those only the appendix shows at the appendix's end
    names = [title for title in tables if title.startswith("Metric names")]
    glossary = pd.concat([md_table(md, title) for title in names]).set_index("metric")
    assert glossary.index.is_unique and len(names) == 2
    used = set()
    for title, df in tables.items():
        if title in names:
            continue
        used |= {c for c in df.columns if c in metrics}
        used |= {t for t in re.findall(r"[a-z][a-z0-9_]*", title) if t in metrics}
        if "key number" in df.columns:
            used |= {t for cell in df["key number"] for t in cell.split(":", 1)[0].split() if t in metrics}
    assert {"heldout_l1", "energy_err_final", "null_heldout_l1", "left_plateau"} <= used
    missing = sorted(used - set(glossary.index))
    assert not missing, missing
    assert not [m for m in used if "not defined" in glossary.loc[m, "meaning"]]
    assert md.index("## Glossary") < md.index("## Double pendulum")   # right after the scorecard
    for term in ("competence bar", "null predictor", "positive control", "development draw", "±"):
        assert f"- {term}" in md[md.index("## Glossary"):md.index("## Double pendulum")], term


def test_no_table_cell_holds_a_raw_record(built):
    md = built["markdown"].read_text()
    findings = md_table(md, "Paper against code")
    assert findings["run here"].str.contains("protocol").any()   # the protocol's records are shown, as text
    for title, df in md_tables(md).items():
        for c in [*df.columns, *df.to_numpy().ravel()]:
            assert "{" not in str(c) and "}" not in str(c), (title, c)


def test_a_yes_no_metric_reads_as_k_of_n_seeds(built):
    md = built["markdown"].read_text()
    k = sum(seed == 0 for seed in SEEDS)   # the fixture's left_plateau is 1 on seed 0 only
    key = claim_rows(md, "Scorecard")[POOLED]["key number"]
    assert key.endswith(f"JAX {k}/{len(SEEDS)} seeds; PyTorch {k}/{len(SEEDS)} seeds"), key
    page = md_table(md, f"{POOLED}: left_plateau (share) per model and framework")
    assert set(page["jax"]) == {f"{k}/{len(SEEDS)} seeds"}
    assert not re.search(r"\b1 ± 0\b", md)


def test_the_index_lists_every_table_and_figure_by_the_number_both_outputs_print(built):
    md = built["markdown"].read_text()
    index = md_table(md, "Tables and figures")
    tables = [int(n) for n in re.findall(r"^\*\*Table (\d+): ", md, re.M)]
    figures = [int(n) for n, _ in FIGURE.findall(md)]
    assert tables == list(range(1, len(tables) + 1))
    listed = set(index["number"])
    assert {f"Figure {n}" for n in figures} <= listed
    assert {f"Table {n}" for n in tables} - listed == {f"Table {n}" for n in tables[-2:]}   # the index's own two
    typ = _both_typst(built)   # REPORT.typ and APPENDIX.typ: every number in one PDF or the other
    assert {int(n) for n in re.findall(r'#strong\("Table (\d+): ', typ)} == set(tables)
