"""Entry point: ``build_report(results_dir, out_dir) -> dict`` (what ``lagbench report`` calls).

Reads only the result files of ``docs/RESULTS.md`` (and ``bench/``), never JAX, PyTorch or
training code. Writes into ``out_dir``: ``REPORT.md``, ``REPORT.typ``, ``REPORT.pdf`` and
``figures/*.png``. Returns ``{"markdown": Path, "typst": Path, "pdf": Path, "figures": [Path, ...]}``.
An empty or missing results folder still yields a report that says nothing was run (the command line
refuses one that holds no results). Writes go through ``reports.output``: atomic, never through a
symlink, and only files an earlier build recorded are ever removed.
"""

from __future__ import annotations

import datetime as dt
from pathlib import Path

from replication.results import writes
from reports import output
from reports.document import Figure, Section, tables_and_figures
from reports.environment import environment_sections, sources_sections
from reports.findings import findings_sections
from reports.load import load_results
from reports.markdown import render_markdown
from reports.pdf import write_pdf
from reports.scorecard import scorecard_section
from reports.sections_claims import metrics_appendix, summary_sections, theme_sections
from reports.sections_fit import fit_sections, is_fit_results
from reports.sections_frameworks import frameworks_sections
from reports.sections_hessian import hessian_sections
from reports.sections_predict import predict_sections
from reports.sections_speed import speed_sections
from reports.sections_stiff import stiff_sections
from reports.systems_table import systems_sections

TITLE = "Replication report: learned Lagrangian and Hamiltonian dynamics"


def build_sections(results_dir: Path, out_dir: Path, now: dt.datetime | None = None) -> list[Section]:
    res = load_results(results_dir)
    mine = predict_sections(results_dir)   # `lagbench evaluate --predict` records, if any
    if is_fit_results(res) or (mine and not res.units):  # fit / evaluate / predict folders: no paper claims
        sections = (fit_sections(res, out_dir) if res.units else []) + mine + environment_sections(res, now)
        return sections + sources_sections(res, sections)
    sections = [scorecard_section(res)] + summary_sections(res)
    sections += theme_sections(res, out_dir)
    sections += speed_sections(res, out_dir)
    sections += frameworks_sections(res)
    sections += hessian_sections(res)
    sections += stiff_sections(res)
    sections += findings_sections(res)
    sections += systems_sections(results_dir) + mine
    sections += environment_sections(res, now)
    sections += metrics_appendix(res)
    return sections + sources_sections(res, sections)


@writes
def build_report(results_dir: str | Path, out_dir: str | Path, *, pdf: bool = True) -> dict:
    """Build REPORT.md (and REPORT.pdf unless ``pdf=False``) from ``results_dir`` into ``out_dir``."""
    out_dir = output.prepare(out_dir)
    sections = build_sections(Path(results_dir), out_dir)
    md = output.write(out_dir / "REPORT.md", render_markdown(TITLE, sections))
    figures = [out_dir / b.path for b in tables_and_figures(sections) if isinstance(b, Figure)]
    paths: dict = {"markdown": md, "figures": figures}
    if pdf:
        paths["typst"], paths["pdf"] = write_pdf(TITLE, sections, out_dir)
    output.finish(out_dir, [md, *figures, *([paths["typst"], paths["pdf"]] if pdf else [])])
    return paths
