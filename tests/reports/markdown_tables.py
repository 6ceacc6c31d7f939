"""Reading the tables of a REPORT.md back: ``md_tables(md)`` -> {title: DataFrame of cell strings}, with the
title as the report prints it less its number ("**Table 3: Scorecard**" is "Scorecard"); ``md_table(md, title)``
one of them; ``claim_rows(md, title)`` a claims table keyed by claim id (its "claim" cell up to a colon)."""
from __future__ import annotations

import re

import pandas as pd

TITLE = re.compile(r"^\*\*(?:Table \d+: )?(.+)\*\*$")


def cells(line: str) -> list[str]:
    return [c.strip() for c in re.split(r"(?<!\\)\|", line.strip())[1:-1]]


def md_tables(md: str) -> dict[str, pd.DataFrame]:
    out, lines = {}, md.splitlines()
    for i, line in enumerate(lines):
        m = TITLE.match(line)
        if not m or i + 2 >= len(lines) or not lines[i + 2].startswith("|"):
            continue
        block = []
        for row in lines[i + 2:]:
            if not row.startswith("|"):
                break
            block.append(row)
        head, body = cells(block[0]), [cells(r) for r in block[2:]]
        out.setdefault(m[1], pd.DataFrame(body, columns=head))
    return out


def md_table(md: str, title: str) -> pd.DataFrame:
    return md_tables(md)[title]


def claim_rows(md: str, title: str) -> dict[str, dict]:
    df = md_table(md, title)
    return {r["claim"].split(":", 1)[0]: r for r in df.to_dict("records")}
