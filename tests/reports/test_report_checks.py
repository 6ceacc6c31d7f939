"""Issue 83, checked mechanically on the report built from the fixtures: every figure's caption names what it
shows, the paper figure it recreates (or none) and its source; no table is wider than the text; the glossary
defines every metric name the tables show; no table cell holds a raw Python record; a yes/no metric reads as
k/n seeds; tables and figures carry the same numbers in REPORT.md and the PDF, and the index lists them all."""
import json
import re

import pandas as pd
import pytest
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


def test_the_glossary_defines_every_column_the_speed_study_tables_can_show():
    """The bench's control-rate and DeLaN-per-dof tables (not in the fixtures' results) are named in full too."""
    from lagbench.reports.glossary import IDENTIFIER, define
    from lagbench.speedstudy import control_rate, delan_dof

    names = [c for c in [*control_rate.COLUMNS, *delan_dof.COLUMNS] if IDENTIFIER.match(c)]
    assert {"rate_hz_mean", "fits_500hz_p99", "us_per_sample"} <= set(names)
    assert not [c for c in names if define(c) is None]


def test_an_interval_level_and_a_threshold_print_to_three_significant_digits():
    from lagbench.reports.reasons import interval_words
    from lagbench.reports.scorecard import round_numbers

    level = 1 - 0.05 / 3   # a Bonferroni level over three rivals
    words = interval_words({"what": "a/b", "point": 0.9, "lo": 0.6, "hi": 1.5, "level": level, "seeds": [8, 8]})
    assert f"{100 * level:.1f} % confidence interval" in words and f"{100 * level:.4f}" not in words
    assert round_numbers(f"within {1.5 ** 0.5}: reproduced; factor 6: reproduced") == (
        "within 1.22: reproduced; factor 6: reproduced")


def test_the_robustness_figure_draws_each_delan_variant_in_the_reports_colour(tmp_path):
    """One colour per model across the report: the study's figure takes the report's (colour-blind safe)
    colours, drawn exactly in its markers; matplotlib's default pair is not left in it."""
    from matplotlib.colors import to_rgb
    from matplotlib.image import imread

    from lagbench.replication.studies.robustness_figure import VARIANTS, advantage_figure
    from lagbench.replication.studies.robustness_scenes import KINDS
    from lagbench.reports.figures import model_colours

    rows = [{"kind": kind, "magnitude": mag, "model": m, "framework": "jax", "seed": s,
             "torque_ratio_to_ff": 0.1 * (1 + mag) * (2 if m == "delan" else 1), "track_ratio_to_ff": 0.2 * (1 + mag)}
            for kind, mags in [("nominal", [0.0])] + [(k, [0.5, 2.0]) for k in KINDS]
            for mag in mags for m in [*VARIANTS, "ff"] for s in (0, 1)]
    colours = model_colours(list(VARIANTS))
    advantage_figure(pd.DataFrame(rows), tmp_path / "a.png", colours)
    pixels = {tuple(p) for p in (imread(tmp_path / "a.png")[..., :3] * 255).round().astype(int).reshape(-1, 3)}
    rgb = {name: tuple(round(255 * c) for c in to_rgb(x)) for name, x in
           {**colours, "default 0": "C0", "default 1": "C1"}.items()}
    assert len(set(colours.values())) == len(VARIANTS)
    assert {n for n, c in rgb.items() if c in pixels} == set(VARIANTS), rgb


@pytest.mark.parametrize("lo, hi", [(5.2e6, 1.15e7), (360.0, 800.0), (2e6, 9e6)])
def test_a_log_axis_within_a_decade_prints_labels_that_do_not_run_into_each_other(lo, hi):
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    from lagbench.reports.figures import new_figure
    from lagbench.reports.figures_precision import label_minor_log

    fig, (ax, _) = new_figure(ncols=2, width=9.0, height=3.6)   # the work-precision figure's panels
    ax.plot([lo, hi], [1.0, 2.0])
    ax.set_xscale("log")
    label_minor_log(ax)
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    renderer = canvas.get_renderer()
    boxes = sorted((t.get_window_extent(renderer) for t in [*ax.get_xticklabels(), *ax.get_xticklabels(minor=True)]
                    if t.get_text() and min(ax.get_xlim()) <= t.get_position()[0] <= max(ax.get_xlim())),
                   key=lambda b: b.x0)
    assert len(boxes) >= 1
    assert all(a.x1 < b.x0 for a, b in zip(boxes, boxes[1:], strict=False)), [(b.x0, b.x1) for b in boxes]


def test_a_training_figure_of_scouted_units_says_why_it_starts_mid_budget(small_results_dir, tmp_path):
    import shutil

    from result_fixtures import checksum, write_json

    from lagbench.reports import build_report

    shutil.copytree(small_results_dir, tmp_path / "res")
    for f in (tmp_path / "res" / "units" / "dp_loss").glob("*/lnn/seed*/result.json"):
        r = json.loads(f.read_text())
        r["scouting"] = {"init_seeds": [16000 + i for i in range(16)], "chosen": 16003}
        r["checksum"] = checksum(r)
        write_json(f, r)
    md = build_report(tmp_path / "res", tmp_path / "out", pdf=False)["markdown"].read_text()
    # the fixture's logs track no held-out loss: its training figure is the training curves
    (caption,) = [text for _, text in FIGURE.findall(md) if text.startswith("dp_loss: Training curves")]
    said = caption.split("Shows:")[0]
    assert " lnn: the log starts where the protocol's scouting ends (16 initialisations" in said, caption
    assert "baseline" not in said   # its units did not scout


def test_a_speed_figure_says_higher_is_better_for_a_share_of_seeds_and_lower_for_an_error(built):
    md = built["markdown"].read_text()
    speed = {text.split(":", 1)[0]: text for _, text in FIGURE.findall(md) if ": speed against " in text}
    assert POOLED in speed and len(speed) > 1
    for claim, text in speed.items():
        way = "higher" if claim == POOLED else "lower"
        assert f"({way} is better)" in text, text
