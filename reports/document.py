"""The report as a neutral document: sections of paragraphs, bullet lists, tables and figures.

Section builders produce a ``list[Section]``; :mod:`reports.markdown` and :mod:`reports.pdf` render the
same list, so both outputs always carry the same numbers. Tables are pandas DataFrames whose cells are
already strings (see :func:`reports.fmt.cell`); figure paths are relative to the output folder.
``number(sections)`` numbers the tables and the figures in reading order (Table 1, Figure 1, ...; a block
numbered already keeps its number), so that both renderers print the same numbers; ``label(block)`` is
"Table 3: <title>" or "Figure 7: <caption, what it shows, the paper figure it recreates (or none) and its
source files>".
"""

from __future__ import annotations

from dataclasses import dataclass, field

import pandas as pd

NOT_RUN = "not run"
NO_PAPER_FIGURE = "none (the suite's own view)"


@dataclass
class Para:
    text: str


@dataclass
class Bullets:
    items: list[str]


@dataclass
class Table:
    """A titled table; ``sources`` name the result files its numbers come from."""

    title: str
    df: pd.DataFrame
    sources: list[str] = field(default_factory=list)
    note: str = ""
    number: int | None = None


@dataclass
class Figure:
    """A PNG (path relative to the output folder) with its caption and source files; ``shows``: the quantity
    plotted (its metric, as the axis reads); ``paper``: the paper figure it recreates ("" for none)."""

    path: str
    caption: str
    sources: list[str] = field(default_factory=list)
    shows: str = ""
    paper: str = ""
    number: int | None = None


@dataclass
class Section:
    """``page``: in the PDF, the section starts a page; ``appendix``: the section opens the appendix (the PDF
    starts a page and numbers the sections from it A, B, ...); ``dump``: a long table dump that REPORT.md
    keeps in its place and the PDF sends to APPENDIX.pdf (``reports.pdf``)."""

    title: str
    blocks: list = field(default_factory=list)
    level: int = 1
    page: bool = False
    appendix: bool = False
    dump: bool = False

    def add(self, *blocks) -> Section:
        self.blocks.extend(b for b in blocks if b is not None)
        return self


def tables_and_figures(sections: list[Section]) -> list[Table | Figure]:
    return [b for s in sections for b in s.blocks if isinstance(b, Table | Figure)]


def number(sections: list[Section]) -> None:
    """Number every table and figure of ``sections`` in reading order, each kind from 1 on (a block numbered
    already keeps its number and the count goes on after the highest)."""
    blocks = tables_and_figures(sections)
    for kind in (Table, Figure):
        mine = [b for b in blocks if isinstance(b, kind)]
        n = max((b.number for b in mine if b.number), default=0)
        for b in mine:
            if b.number is None:
                n += 1
                b.number = n


def label(b: Table | Figure) -> str:
    if isinstance(b, Table):
        return f"Table {b.number}: {b.title}" if b.number else b.title
    text = b.caption.rstrip()
    if b.shows:
        text += f" Shows: {b.shows}."
    text += f" Paper figure: {b.paper or NO_PAPER_FIGURE}."
    text += f" Source: {'; '.join(b.sources) or 'computed'}."
    return f"Figure {b.number}: {text}" if b.number else text

