"""The report a reader gets through: a body of the scorecard, a page per claim (its verdict, parts, decisive
numbers and figures) and speed against error, with every dump, table of counters and study in the appendix."""
import pytest
from result_fixtures import CLAIMS, NOT_RUN_CLAIM

from lagbench.reports.build import TITLE, body_and_appendix
from lagbench.reports.document import Figure, Table, label
from lagbench.reports.pdf import page_count, write_pdf

DUMPS = ("competence bars", "rollout metrics", "all recorded metrics", "Reasons in full", "Parts of the paper claims",
         "Registered protocols", "Tuning ledger", "Units per claim")


@pytest.fixture(scope="module")
def sections(results_dir, tmp_path_factory):
    """(body, appendix, folder): the report's sections built once from the fixture results into folder."""
    folder = tmp_path_factory.mktemp("structure")
    return (*body_and_appendix(results_dir, folder), folder)


def test_every_claim_has_a_page_with_its_numbers_and_a_figure_and_the_dumps_are_in_the_appendix(sections):
    body, appendix, _ = sections
    pages = {s.title.split(": ", 1)[1]: s for s in body if s.title.startswith("Claim ")}
    assert set(pages) == {c[0] for c in CLAIMS}
    for cid, page in pages.items():
        tables = [b.title for b in page.blocks if isinstance(b, Table)]
        assert f"{cid}: parts per framework" in tables or cid == NOT_RUN_CLAIM
        if cid != NOT_RUN_CLAIM:
            assert any("per model and framework" in t for t in tables), cid   # the decisive numbers
            assert any(isinstance(b, Figure) for b in page.blocks) or cid == "appendix_b", cid
    assert not [s.title for s in pages.values() if s.page]   # the claims flow on: the body stays short
    body_tables = [b.title for s in body for b in s.blocks if isinstance(b, Table)]
    assert not [t for t in body_tables if any(d in t for d in DUMPS)]
    app_tables = [b.title for s in appendix for b in s.blocks if isinstance(b, Table)]
    for d in ("competence bars", "all recorded metrics", "Parts of the paper claims", "Units per claim"):
        assert any(d in t for t in app_tables), d
    assert appendix[0].appendix and not any(s.appendix for s in body + appendix[1:])
    titles = [s.title for s in appendix]
    assert {"Cross-framework agreement", "Environment", "Findings: paper against original code"} <= set(titles)


def test_the_papers_figures_are_recreated_with_the_figure_each_stands_for(sections):
    body, _, folder = sections
    captions = {s.title.split(": ", 1)[1]: [label(b) for b in s.blocks if isinstance(b, Figure)]
                for s in body if s.title.startswith("Claim ")}
    for cid, figure in (("dp_energy", "LNN Fig. 2(b)"), ("dp_energy", "LNN Fig. 2(a)"), ("rel_coords", "LNN Fig. 3"),
                        ("wave_lgn", "LNN Fig. 4 ("), ("wave_lgn", "energy integrated across the material"),
                        ("hnn_energy", "HNN Fig. 2's total-energy column")):
        assert any(figure in c for c in captions[cid]), (cid, figure)
    # the relativistic rollouts are drawn once, as the paper's per-model panels
    assert not any("Trajectory: truth against each model" in c for c in captions["rel_coords"])
    assert (folder / "figures" / "rel_coords_panels.png").stat().st_size > 0


def test_the_body_is_short_and_the_appendix_starts_a_page(sections):
    body, appendix, folder = sections
    assert body[1].title == "Glossary"   # the terms right after the scorecard; the rest of the body is short
    _, pdf = write_pdf(TITLE, body[:1] + body[2:], folder)
    assert page_count(pdf) <= 20
    _, pdf = write_pdf(TITLE, body, folder)
    n_body = page_count(pdf)
    pdf = write_pdf(TITLE, body + appendix, folder)[1]
    assert page_count(pdf) > n_body
    typ = (folder / "REPORT.typ").read_text()
    assert typ.index('#set heading(numbering: "A.1")') < typ.index('"Appendix"')


def test_a_model_kind_keeps_its_colour_from_figure_to_figure():
    from lagbench.reports.figures import model_colours

    a = model_colours(["lnn", "baseline"])
    b = model_colours(["baseline_spring", "hnn_spring"])
    c = model_colours(["delan_relativistic", "lnn_relativistic"])
    assert a["lnn"] == c["lnn_relativistic"] and a["baseline"] == b["baseline_spring"]
    assert len(set(a.values())) == 2 and len(set(b.values())) == 2
    ablation = model_colours(["lnn_act-softplus", "lnn_act-relu", "lnn_act-tanh"])   # one kind: by order
    assert len(set(ablation.values())) == 3
    kinds = model_colours(["baseline", "lnn", "hnn", "delan", "lgn", "ff"])
    for sweep in (["hnn_spring", "baseline_spring", "hnn_pendulum", "baseline_pendulum"],
                  ["baseline_f32", "baseline_f64"], ["delan", "delan_n1024", "delan_n256", "ff", "ff_n1024", "ff_n256"],
                  [*ablation]):
        got = model_colours(sweep)
        assert len(set(got.values())) == len(sweep), got   # one colour per arm
        for arm, c in got.items():   # its own kind's colour or one no kind of the figure owns
            assert c == kinds[arm.split("_", 1)[0]] or c not in kinds.values(), (arm, c)
        assert set(got.values()) >= {kinds[x.split("_", 1)[0]] for x in sweep}   # each kind keeps its colour


def test_no_figure_keeps_a_linear_axis_over_more_than_three_decades(results_dir, tmp_path, monkeypatch):
    import numpy as np

    from lagbench.reports import figures as F
    from lagbench.reports.build import build_sections

    fig, (ax,) = F.new_figure()
    ax.plot([0, 1, 2], [1e-3, 1.0, 1e2])
    F.save(fig, tmp_path / "x.png")
    assert ax.get_yscale() == "log" and ax.get_xscale() == "linear"   # x spans 0-2 (a zero is no decade)
    fig, (ax,) = F.new_figure()
    ax.plot([0, 1], [-1e3, 1e-2])   # both signs: stays linear
    F.save(fig, tmp_path / "y.png")
    assert ax.get_yscale() == "linear"

    spans = []
    real = F.save

    def check(fig, path):
        out = real(fig, path)
        spans.extend(F.linear_span(a, axis) for a in fig.axes for axis in ("x", "y"))
        return out
    from lagbench.reports import figures_precision, figures_speed

    for module in (F, figures_precision, figures_speed):
        monkeypatch.setattr(module, "save", check)
    build_sections(results_dir, tmp_path / "report")
    assert spans and max(spans) <= F.LINEAR_DECADES and np.isfinite(spans).all()
