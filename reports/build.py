"""Entry point: ``build_report(results_dir, out_dir) -> dict`` (what ``lagbench report`` calls).

Reads only the result files of ``docs/RESULTS.md`` (and ``bench/``), never JAX, PyTorch or
training code. The sections are built, their tables tidied (``reports.tidy``), the glossary set after the
scorecard (``reports.glossary``), every table and figure numbered (``document.number``) and the index of them
added last, so that REPORT.md and the PDF carry the same numbers. Writes into ``out_dir``: ``REPORT.md``, ``REPORT.typ``, ``REPORT.pdf`` and
``figures/*.png``, and ``APPENDIX.typ`` and ``APPENDIX.pdf`` where the report has long dumps (sections marked
``dump``: REPORT.md keeps them in place, ``reports.pdf`` sends them to the second PDF), built aside and moved in
as a whole (``reports.output``). Returns ``{"markdown": Path,
"typst": Path, "pdf": Path, "figures": [Path, ...]}`` (with ``"appendix_pdf": Path`` where APPENDIX.pdf is
written), and ``"not_rebuilt": [Path, ...]`` where a ``--no-pdf`` build leaves a PDF or typst source it did
not write and may not remove (not on record,
or changed since).
The title says what the folder holds (`titled`): the replication report, a fit report (`lagbench fit` /
`evaluate` units) or a predictor report (`evaluate --predict` records alone).
An empty or missing results folder still yields a report that says nothing was run (the command line
refuses one that holds no results). Writes go through ``reports.output``: atomic, never through a
symlink, and only files an earlier build recorded are ever removed.
"""

from __future__ import annotations

import datetime as dt
import os
from pathlib import Path

from lagbench.files.results import writes
from lagbench.reports import output
from lagbench.reports.document import Figure, Para, Section, number, tables_and_figures
from lagbench.reports.environment import environment_sections, sources_sections
from lagbench.reports.findings import findings_sections
from lagbench.reports.glossary import glossary_section, more_metric_names
from lagbench.reports.load import load_results
from lagbench.reports.markdown import render_markdown
from lagbench.reports.pdf import write_pdf
from lagbench.reports.scorecard import scorecard_appendix, scorecard_section
from lagbench.reports.sections_claims import claim_details, metrics_appendix, summary_sections, theme_sections
from lagbench.reports.sections_control import control_sections
from lagbench.reports.sections_cost import cost_sections
from lagbench.reports.sections_fit import fit_sections, is_fit_results
from lagbench.reports.sections_frameworks import frameworks_sections
from lagbench.reports.sections_hessian import hessian_sections
from lagbench.reports.sections_online import online_sections
from lagbench.reports.sections_predict import predict_sections
from lagbench.reports.sections_robustness import robustness_sections
from lagbench.reports.sections_speed import speed_appendix, speed_sections
from lagbench.reports.sections_stiff import stiff_sections
from lagbench.reports.sections_verify import verify_sections
from lagbench.reports.systems_table import systems_sections
from lagbench.reports.tidy import tidy

PDF_FILES = ("REPORT.typ", "REPORT.pdf", "APPENDIX.typ", "APPENDIX.pdf")   # what the PDF build writes
TITLE = "Replication report: learned Lagrangian and Hamiltonian dynamics"
FIT_TITLE = "Fit report: models trained on your data (lagbench fit, lagbench evaluate)"
PREDICT_TITLE = "Predictor report: your functions scored as the suite scores its models (lagbench evaluate --predict)"


APPENDIX = ("What the body's numbers rest on: the published numbers beside ours, every part with its interval, "
            "the variants, the reasons in full, the registrations and the tuning ledger, the run's status, the "
            "findings (paper against original code), the cross-framework comparison, the stiff-solver study, the "
            "speed study and the environment; and the long tables: each claim's details (its models' sizes, "
            "competence and rollout tables), each unit's speed against error, the velocity-Hessian health, the "
            "results by system, every recorded metric, the appendix's metric names and the index of every table "
            "and figure with its source files.")


def _dumps(sections: list[Section]) -> list[Section]:
    """``sections`` marked as long dumps: REPORT.md keeps them in place, the PDF sends them to APPENDIX.pdf."""
    for s in sections:
        s.dump = True
    return sections


def _finish(body: list[Section], appendix: list[Section], res) -> tuple[list, list]:
    """Tables tidied (`reports.tidy`), the glossary after the scorecard (the body's first section) when the
    report has one (the metric names the body shows; those only the appendix shows at the appendix's end),
    every table and figure numbered, and the index of them closing the appendix."""
    tidy(body + appendix)
    if body and body[0].title == "Scorecard":   # the body's metric names after the scorecard, the rest in a dump
        body.insert(1, glossary_section(body))
        appendix += _dumps(more_metric_names(appendix, body))
    number(body + appendix)
    index = sources_sections(res, body + appendix)
    number(body + appendix + index)
    return body, appendix + (_dumps(index) if appendix else index)


def titled(results_dir: Path, out_dir: Path, now: dt.datetime | None = None) -> tuple[str, list, list]:
    """The report's title, body and appendix: a folder of `lagbench fit` / `evaluate` units is a fit report,
    one of `evaluate --predict` records alone a predictor report (neither speaks of the papers' claims, a
    profile or a run); any other is the replication report (`body_and_appendix`)."""
    res = load_results(results_dir)
    mine = predict_sections(results_dir)   # `lagbench evaluate --predict` records, if any
    if is_fit_results(res) or (mine and not res.units):  # fit / evaluate / predict folders: no paper claims
        sections = (fit_sections(res, out_dir) if res.units else []) + mine + environment_sections(res, now)
        return (FIT_TITLE if res.units else PREDICT_TITLE, *_finish(sections, [], res))
    moved: dict = {}   # tables and figures a claim's page sends to its details in the appendix
    body = [scorecard_section(res)] + theme_sections(res, out_dir, moved) + control_sections(res, out_dir)
    body += online_sections(res, out_dir)
    body += robustness_sections(res, out_dir)
    speed = speed_sections(res, out_dir)   # speed against error; the bench studies under it go to the appendix
    body += speed[:1]
    for s in speed[1:]:
        s.level = 1
    first = scorecard_appendix(res)
    first.level = 2   # under the appendix's heading, on its page: the heading never stands alone on a page
    appendix = [Section("Appendix", appendix=True).add(Para(APPENDIX)), first]
    appendix += summary_sections(res) + verify_sections(res) + cost_sections(res) + _dumps(claim_details(res, moved) + speed_appendix(res, out_dir))
    appendix += findings_sections(res) + frameworks_sections(res) + _dumps(hessian_sections(res)) + stiff_sections(res) + speed[1:]
    appendix += _dumps(systems_sections(results_dir)) + mine + environment_sections(res, now)
    appendix += _dumps(metrics_appendix(res))
    return (TITLE, *_finish(body, appendix, res))


def body_and_appendix(results_dir: Path, out_dir: Path, now: dt.datetime | None = None) -> tuple[list, list]:
    """The report's body (the scorecard, the glossary, a page per claim with its figures, the closed-loop
    control and robustness studies, speed against error) and its appendix (everything else), as two lists of
    sections, tables tidied and every table and figure numbered."""
    return titled(results_dir, out_dir, now)[1:]


def build_sections(results_dir: Path, out_dir: Path, now: dt.datetime | None = None) -> list[Section]:
    body, appendix = body_and_appendix(results_dir, out_dir, now)
    return body + appendix


@writes
def build_report(results_dir: str | Path, out_dir: str | Path, *, pdf: bool = True) -> dict:
    """Build REPORT.md (and REPORT.pdf unless ``pdf=False``) from ``results_dir`` into ``out_dir``: written
    aside (``reports.output``'s staging folder), then moved in as a whole. Without typst, the Markdown and
    figures are moved in and the previous build's PDF removed before the error is raised."""
    stage = output.prepare(out_dir)
    out_dir = Path(out_dir)
    failure = None
    try:
        title, body, appendix = titled(Path(results_dir), stage)
        sections = body + appendix
        built = [output.write(stage / "REPORT.md", render_markdown(title, sections))]
        built += list(dict.fromkeys(stage / b.path for b in tables_and_figures(sections) if isinstance(b, Figure)))
        if pdf:
            try:
                built += write_pdf(title, sections, stage)
            except ValueError as e:   # typst missing: what is built is kept, never beside the old PDF
                failure = e
        moved, removed = output.finish(out_dir, built)
    finally:
        output.discard()   # a build that failed or was interrupted: the previous report stays whole
    if failure is not None:
        gone = sorted(p.name for p in removed if p.name in PDF_FILES)
        note = f"; the previous build's {' and '.join(gone)} removed" if gone else ""
        raise ValueError(f"{failure} (REPORT.md and its figures were written{note})") from failure
    paths: dict = {"markdown": moved[0], "figures": [p for p in moved if p.parent.name == "figures"]}
    if pdf:
        paths["typst"], paths["pdf"] = out_dir / "REPORT.typ", out_dir / "REPORT.pdf"
        if out_dir / "APPENDIX.pdf" in moved:
            paths["appendix_pdf"] = out_dir / "APPENDIX.pdf"
    stale = [out_dir / n for n in PDF_FILES if not pdf and os.path.lexists(out_dir / n)]
    if stale:   # not this build's and not on record as an unchanged earlier output: left as it is, and said so
        paths["not_rebuilt"] = stale
    return paths
