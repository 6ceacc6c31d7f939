"""Tables a reader can read on a page: a pass over the built sections before they are rendered.

``tidy(sections)`` rewrites every table in place: a column with no value in any row (every cell one of
``EMPTY``) is left out, and the table's note names it; a table of more than ``MAX_COLUMNS`` columns becomes
several, each repeating the identifying columns it opens with (``ID_COLUMNS``, at most ``MAX_ID``), titled
"(part i of n)". Both renderers then show the same tables (``reports.pdf`` sizes the columns of each).
"""
from __future__ import annotations

from lagbench.reports.document import Section, Table

MAX_COLUMNS = 9
MAX_ID = 3
EMPTY = {"", "–", "-", "nan", "NaN", "None", "not recorded"}
ID_COLUMNS = {"#", "claim", "model", "framework", "seed", "system", "unit", "protocol", "controller", "study",
              "source", "line", "part", "references", "operation"}


def _empty_columns(t: Table) -> list[str]:
    if not len(t.df) or len(t.df.columns) < 2:
        return []
    return [c for c in t.df.columns[1:] if t.df[c].astype(str).str.strip().isin(EMPTY).all()]


def _split(t: Table) -> list[Table]:
    cols = list(t.df.columns)
    if len(cols) <= MAX_COLUMNS:
        return [t]
    ids = []
    for c in cols[:MAX_ID]:
        if str(c) not in ID_COLUMNS:
            break
        ids.append(c)
    ids = ids or cols[:1]
    rest = [c for c in cols if c not in ids]
    per = MAX_COLUMNS - len(ids)
    chunks = [rest[i:i + per] for i in range(0, len(rest), per)]
    return [Table(f"{t.title} (part {i} of {len(chunks)})", t.df[ids + chunk].copy(), list(t.sources),
                  t.note if i == len(chunks) else "") for i, chunk in enumerate(chunks, 1)]


def tidy_table(t: Table) -> list[Table]:
    gone = _empty_columns(t)
    if gone:
        t.df = t.df.drop(columns=gone)
        t.note = (t.note + " " if t.note else "") + f"Left out, with no value in any row: {', '.join(map(str, gone))}."
    return _split(t)


def tidy(sections: list[Section]) -> None:
    for s in sections:
        blocks = []
        for b in s.blocks:
            blocks.extend(tidy_table(b) if isinstance(b, Table) and b.number is None else [b])
        s.blocks = blocks
