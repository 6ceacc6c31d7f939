"""PDF rendering through typst: a ``list[Section]`` becomes ``REPORT.typ``, compiled to ``REPORT.pdf``.

All report text enters the typst source as string literals (``"..."`` with ``\\`` and ``"`` escaped), so
no report content is ever parsed as typst markup. Tables use a small font scaled down with the number
of columns, wrap inside their cells and break across pages (portrait throughout: at 6 pt ten columns
fit). Figures are embedded from ``figures/`` relative to the output folder (the typst root).
"""

from __future__ import annotations

import re
from pathlib import Path

from lagbench.reports.document import Bullets, Figure, Para, Section, Table
from lagbench.reports.output import write

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def figure_width(path: Path) -> str:
    """50 % of the text width for single-panel figures, 75 % for wide multi-panel ones: a claim's page holds
    its tables and two figures (at 55 % and 100 % the quick report's body took 23 pages, at these 20)."""
    try:
        with open(path, "rb") as f:
            head = f.read(24)
        w, h = int.from_bytes(head[16:20], "big"), int.from_bytes(head[20:24], "big")
    except OSError:
        return "50%"
    if not head.startswith(PNG_SIGNATURE) or h == 0:
        return "50%"
    return "75%" if w / h > 2.4 else "50%"


PREAMBLE = """#set document(title: {title})
#set page(paper: "a4", margin: (x: 1.6cm, y: 1.8cm), numbering: "1 / 1")
#set text(size: 10pt)
#set par(justify: false)
#set heading(numbering: "1.1")
#show heading.where(level: 1, outlined: true): it => {{ pagebreak(weak: true); it }}
#show table.cell.where(y: 0): strong
"""


# scripts the fonts typst ships (Libertinus, New Computer Modern, DejaVu Sans Mono) have no glyphs for:
# CJK, kana, Hangul, Yi, full-width forms, emoji and the supplementary planes; the PDF shows them as U+XXXX
# (the Markdown report keeps them as they are) rather than as empty boxes
_NO_GLYPH = re.compile("[\u2e80-\ua4cf\uac00-\ud7af\uf900-\ufaff\ufe30-\ufe4f\uff00-\uffef\U0001f000-\U0010ffff]")


def lit(text) -> str:
    """A typst string literal holding ``text`` verbatim (characters no shipped font can show as U+XXXX)."""
    s = _NO_GLYPH.sub(lambda m: f"U+{ord(m.group()):04X}", str(text))
    s = s.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n").replace("\r", "")
    s = re.sub(r"[\x00-\x08\x0b-\x1f]", " ", s)
    return f'"{s}"'


def _table(t: Table) -> str:
    ncol = max(len(t.df.columns), 1)
    size = 8 if ncol <= 4 else (7 if ncol <= 7 else 6)
    cells = [lit(c) for c in t.df.columns]
    for row in t.df.itertuples(index=False):
        cells += [lit(str(v).strip() or "not run") for v in row]
    body = (f"#text(size: {size}pt)[#table(columns: {ncol}, inset: 3pt, stroke: 0.4pt + gray, align: left,\n"
            f"  table.header({', '.join(cells[:ncol])}),\n  {', '.join(cells[ncol:])})]")
    out = f"#strong({lit(t.title)})\n\n{body}\n"
    if t.note:
        out += f"\n#emph({lit(t.note)})\n"
    return out + "\n"


def render_typst(title: str, sections: list[Section], root: Path = Path(".")) -> str:
    out = [PREAMBLE.format(title=lit(title)),
           f"#align(center, text(size: 18pt, weight: \"bold\", {lit(title)}))\n",
           "#outline(depth: 1)\n"]
    for s in sections:
        if s.appendix:
            out.append('#pagebreak(weak: true)\n#counter(heading).update(0)\n#set heading(numbering: "A.1")\n')
        elif s.page:
            out.append("#pagebreak(weak: true)\n")
        out.append(f"#heading(level: {s.level}, {lit(s.title)})\n")
        for b in s.blocks:
            if isinstance(b, Para):
                out.append(f"#{lit(b.text)}\n")
            elif isinstance(b, Bullets):
                out.append("#list(" + ", ".join(lit(i) for i in b.items) + ")\n")
            elif isinstance(b, Table):
                out.append(_table(b))
            elif isinstance(b, Figure):
                width = figure_width(root / b.path)
                out.append(f"#figure(image({lit(b.path)}, width: {width}), caption: {lit(b.caption)})\n")
    return "\n".join(out)


def write_pdf(title: str, sections: list[Section], out_dir: Path) -> tuple[Path, Path]:
    """Write ``REPORT.typ`` and compile ``REPORT.pdf`` in ``out_dir``; returns both paths."""
    try:
        import typst  # a core dependency, imported here so that importing `reports` stays light
    except ImportError as e:
        raise ValueError(f"the PDF report needs typst ({e}): pip install typst, or write the Markdown report "
                         f"alone with `lagbench report --no-pdf`") from e

    out_dir = Path(out_dir)
    typ = out_dir / "REPORT.typ"
    pdf = out_dir / "REPORT.pdf"
    write(typ, render_typst(title, sections, out_dir))
    write(pdf, typst.compile(str(typ), root=str(out_dir.resolve())))  # bytes, written atomically
    return typ, pdf


def page_count(pdf: Path) -> int:
    """Pages of a typst-written PDF (page objects are not compressed into object streams)."""
    return len(re.findall(rb"/Type\s*/Page\b", Path(pdf).read_bytes()))
