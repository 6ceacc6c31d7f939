"""PDF rendering through typst: a ``list[Section]`` becomes ``REPORT.typ``, compiled to ``REPORT.pdf``.

All report text enters the typst source as string literals (``"..."`` with ``\\`` and ``"`` escaped), so
no report content is ever parsed as typst markup. Tables use a small font scaled down with the number
of columns (8 pt up to 4 columns, 7 pt up to 7, 6 pt beyond; ``reports.tidy`` splits a table of more than
``tidy.MAX_COLUMNS``), wrap inside their cells, hyphenate, and break across pages (portrait throughout).
Every column gets an explicit width (``column_widths``): at least its longest unbreakable run of characters,
the rest of the text width shared by how much each column holds, so that no header or cell runs over its
neighbour or past the margin; a run longer than ``RUN`` characters (a path, a long identifier) is given
break points after ``_``, ``/``, ``,`` and ``=``, and every ``RUN`` characters where it has none
(``breakable``). Tables and figures carry the report's numbers (``document.label``); typst's own figure
numbering is off, so the PDF and REPORT.md print the same "Figure 7". Figures are embedded from
``figures/`` relative to the output folder (the typst root), at a width from their size in inches.

The body flows on from section to section (a level-1 section starts a page in the appendix, or where it asks
to with ``page``). The long dumps (sections marked ``dump``) leave REPORT.pdf for a
second PDF, ``APPENDIX.pdf`` (``APPENDIX.typ``), rendered from the same sections with the same numbers; the
main PDF's appendix says in one line where they are (``write_pdf``).
"""

from __future__ import annotations

import re
from pathlib import Path

from lagbench.reports.document import Bullets, Figure, Para, Section, Table, label
from lagbench.reports.figures import DPI
from lagbench.reports.output import write

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def figure_width(path: Path) -> str:
    """The share of the text width (7 in) a figure takes, from its width in inches at ``figures.DPI``: a single
    panel (up to 7 in) 45 %, a wider one 60 %, a figure of many panels (over 10 in, or wider than 2.4 x its
    height) 80 %, so that a figure's lettering stays near the size of the caption's and the body stays short."""
    try:
        with open(path, "rb") as f:
            head = f.read(24)
        w, h = int.from_bytes(head[16:20], "big"), int.from_bytes(head[20:24], "big")
    except OSError:
        return "45%"
    if not head.startswith(PNG_SIGNATURE) or h == 0:
        return "45%"
    inches = w / DPI
    if inches > 10 or w / h > 2.4:
        return "80%"
    return "60%" if inches > 7 else "45%"


TEXT_WIDTH = 504.0   # pt: A4 (595 pt) less the 1.6 cm margins
INSET = 3.0          # pt, each side of a cell
RUN = 16             # the longest run of characters a table cell keeps without a break point
ZWSP = "\u200b"      # a break point that prints nothing


def breakable(text: str) -> str:
    """``text`` with break points in every run of more than `RUN` characters without a space: after ``_``,
    ``/``, ``,``, ``;`` and ``=``, then every `RUN` characters of a piece still longer."""
    def split(word: str) -> str:
        if len(word) <= RUN:
            return word
        pieces = re.split(r"(?<=[_/,;=])", word)
        return ZWSP.join(ZWSP.join(p[i:i + RUN] for i in range(0, len(p), RUN)) for p in pieces if p)
    return re.sub(r"\S+", lambda m: split(m.group()), str(text))


def longest_run(text: str) -> int:
    """The longest run of characters ``text`` keeps without a space or a break point."""
    return max((len(w) for w in re.split(f"[\\s{ZWSP}]+", str(text))), default=0)


def font_size(ncol: int) -> int:
    return 8 if ncol <= 4 else (7 if ncol <= 7 else 6)


def column_widths(columns: list[list[str]], size: float) -> list[float]:
    """Widths in pt of columns of cells (header first, after `breakable`): each at least its longest run at
    0.6 em a character (no glyph of the fonts is wider on average) plus the insets, and at most what its
    longest cell needs (0.5 em a character); the text width shared between them by their mean cell length (a
    row is as high as its tallest cell, whose height goes as its length over its width: equal heights are
    the lowest rows)."""
    pad = 2 * INSET + 1
    least = [longest_run(" ".join(c)) * 0.6 * size + pad for c in columns]
    most = [max(lo, max((len(x) for x in c), default=0) * 0.5 * size + pad) for c, lo in zip(columns, least, strict=True)]
    if sum(most) <= TEXT_WIDTH or sum(least) >= TEXT_WIDTH:
        return most if sum(most) <= TEXT_WIDTH else least
    weight = [max(sum(len(x) for x in c) / max(len(c), 1), 1.0) for c in columns]
    fixed: dict[int, float] = {}
    while True:   # water-filling: shares by weight, a column held at its least or its most where a share passes it
        free = [j for j in range(len(columns)) if j not in fixed]
        room = TEXT_WIDTH - sum(fixed.values())
        total = sum(weight[j] for j in free)
        width = {j: room * weight[j] / total for j in free}
        low = {j: least[j] for j in free if width[j] < least[j]}
        high = {j: most[j] for j in free if width[j] > most[j]}
        if not low and not high:
            return [fixed.get(j, width.get(j)) for j in range(len(columns))]
        fixed.update(low or high)


PREAMBLE = """#set document(title: {title})
#set page(paper: "a4", margin: (x: 1.6cm, y: 1.8cm), numbering: "1 / 1")
#set text(size: 10pt)
#set par(justify: false)
#set heading(numbering: "1.1")
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
    size = font_size(ncol)
    columns = [[breakable(c)] + [breakable(str(v).strip() or "not run") for v in t.df.iloc[:, j]]
               for j, c in enumerate(t.df.columns)]
    widths = column_widths(columns, size)
    head = [lit(c[0]) for c in columns]
    cells = [lit(columns[j][i]) for i in range(1, len(t.df) + 1) for j in range(ncol)]
    body = (f"#text(size: {size}pt, hyphenate: true)[#table(columns: ({', '.join(f'{w:.1f}pt' for w in widths)},), "
            f"inset: {INSET:g}pt, stroke: 0.4pt + gray, align: left,\n"
            f"  table.header({', '.join(head)}),\n  {', '.join(cells)})]")
    out = f"#strong({lit(label(t))})\n\n{body}\n"
    if t.note:
        out += f"\n#emph({lit(t.note)})\n"
    return out + "\n"


def render_typst(title: str, sections: list[Section], root: Path = Path(".")) -> str:
    out = [PREAMBLE.format(title=lit(title)),
           f"#align(center, text(size: 18pt, weight: \"bold\", {lit(title)}))\n",
           "#outline(depth: 1)\n"]
    appendix = False
    for s in sections:
        if s.appendix:
            appendix = True
            out.append('#pagebreak(weak: true)\n#counter(heading).update(0)\n#set heading(numbering: "A.1")\n')
        elif s.page or (s.level == 1 and appendix):
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
                out.append(f"#figure(image({lit(b.path)}, width: {width}), numbering: none, "
                           f"caption: {lit(label(b))})\n")
    return "\n".join(out)


APPENDIX_PDF = "APPENDIX.pdf"


def split(title: str, sections: list[Section]) -> tuple[list[Section], list[Section], str]:
    """(REPORT.pdf's sections, APPENDIX.pdf's, APPENDIX.pdf's title): the sections marked ``dump`` go to the
    second, and the main PDF's appendix opens with a line naming them and where they are."""
    dumps = [s for s in sections if s.dump]
    main = [s for s in sections if not s.dump]
    if not dumps:
        return main, [], ""
    names = "; ".join(s.title for s in dumps if s.level == 1)
    where = Para(f"In {APPENDIX_PDF}, beside this file (and in REPORT.md, in full): {names}.")
    at = next((i for i, s in enumerate(main) if s.appendix), None)
    if at is None:
        main.append(Section("Appendix", appendix=True).add(where))
    else:
        opening = main[at]
        main[at] = Section(opening.title, [*opening.blocks, where], opening.level, opening.page, True)
    return main, dumps, f"{title}: appendix of long tables"


def write_pdf(title: str, sections: list[Section], out_dir: Path) -> tuple[Path, ...]:
    """Write ``REPORT.typ`` and compile ``REPORT.pdf`` in ``out_dir``, and ``APPENDIX.typ`` and
    ``APPENDIX.pdf`` where sections are marked ``dump`` (`split`); returns the paths written."""
    try:
        import typst  # a core dependency, imported here so that importing `reports` stays light
    except ImportError as e:
        raise ValueError(f"the PDF report needs typst ({e}): pip install typst, or write the Markdown report "
                         f"alone with `lagbench report --no-pdf`") from e

    out_dir = Path(out_dir)
    main, dumps, second = split(title, sections)
    written: list[Path] = []
    for name, heading, part in (("REPORT", title, main), ("APPENDIX", second, dumps)):
        if not part:
            continue
        typ, pdf = out_dir / f"{name}.typ", out_dir / f"{name}.pdf"
        write(typ, render_typst(heading, part, out_dir))
        write(pdf, typst.compile(str(typ), root=str(out_dir.resolve())))  # bytes, written atomically
        written += [typ, pdf]
    return tuple(written)


def page_count(pdf: Path) -> int:
    """Pages of a typst-written PDF (page objects are not compressed into object streams)."""
    return len(re.findall(rb"/Type\s*/Page\b", Path(pdf).read_bytes()))
