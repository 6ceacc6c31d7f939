"""Markdown rendering of a ``list[Section]`` (GitHub-flavoured pipe tables; no tabulate dependency).

Cells are escaped (``|`` becomes ``\\|``, newlines ``<br>``); an empty cell becomes ``"not run"``.
Figures are embedded with paths relative to the Markdown file. Tables and figures carry the numbers the PDF
prints ("Table 3: ...", "Figure 7: ...", ``document.label``); the report's index of them is its appendix
"Index of tables and figures".
"""

from __future__ import annotations

import pandas as pd

from lagbench.reports.document import NOT_RUN, Bullets, Figure, Para, Section, Table, label


def _escape(text) -> str:
    t = str(text).strip()
    return (t or NOT_RUN).replace("|", "\\|").replace("\r", "").replace("\n", "<br>")


def table_markdown(df: pd.DataFrame) -> str:
    cols = [_escape(c) for c in df.columns]
    lines = ["| " + " | ".join(cols) + " |", "|" + "|".join("---" for _ in cols) + "|"]
    for row in df.itertuples(index=False):
        lines.append("| " + " | ".join(_escape(v) for v in row) + " |")
    return "\n".join(lines)


def render_markdown(title: str, sections: list[Section]) -> str:
    out = [f"# {title}", ""]
    toc = [s for s in sections if s.level == 1]
    out += [f"- {s.title}" for s in toc] + [""]
    for s in sections:
        out += [f"{'#' * (s.level + 1)} {s.title}", ""]
        for b in s.blocks:
            if isinstance(b, Para):
                out += [b.text, ""]
            elif isinstance(b, Bullets):
                out += [f"- {item}" for item in b.items] + [""]
            elif isinstance(b, Table):
                out += [f"**{label(b)}**", "", table_markdown(b.df), ""]
                if b.note:
                    out += [f"_{b.note}_", ""]
            elif isinstance(b, Figure):
                alt = f"Figure {b.number}" if b.number else "figure"
                out += [f"![{alt}]({b.path})", "", f"*{label(b)}*", ""]
    return "\n".join(out).rstrip() + "\n"
