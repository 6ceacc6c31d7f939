"""The report as a neutral document: sections of paragraphs, bullet lists, tables and figures.

Section builders produce a ``list[Section]``; :mod:`reports.markdown` and :mod:`reports.pdf` render the
same list, so both outputs always carry the same numbers. Tables are pandas DataFrames whose cells are
already strings (see :func:`reports.fmt.cell`); figure paths are relative to the output folder.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import pandas as pd

NOT_RUN = "not run"


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


@dataclass
class Figure:
    """A PNG (path relative to the output folder) with its caption and source files."""

    path: str
    caption: str
    sources: list[str] = field(default_factory=list)


@dataclass
class Section:
    """``page``: in the PDF, the section starts a page (a claim's page); ``appendix``: the section opens the
    appendix (the PDF starts a page and numbers the sections from it A, B, ...)."""

    title: str
    blocks: list = field(default_factory=list)
    level: int = 1
    page: bool = False
    appendix: bool = False

    def add(self, *blocks) -> Section:
        self.blocks.extend(b for b in blocks if b is not None)
        return self


def tables_and_figures(sections: list[Section]) -> list[Table | Figure]:
    return [b for s in sections for b in s.blocks if isinstance(b, Table | Figure)]
