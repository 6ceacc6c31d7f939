"""The README's claims table, made from a run's `claims.json` and `summary/verdicts.json` (never by hand).

`table(claims, verdicts) -> str`: one Markdown row per paper claim, then per check: number, title, where in
the paper, the verdict, each counted part with its verdict, the key model's metric in JAX and PyTorch (the
seed mean) and the published value with what kind of number it is; below it, one line per variant.
`python -m lagbench.reports.readme_table FOLDER` prints it from FOLDER/claims.json and FOLDER/verdicts.json (a
sample-report folder) or FOLDER/summary/verdicts.json (a results folder), between markers that name FOLDER
(`begin(folder)`, `END`). The README holds such blocks, each the output on the committed folder its marker
names (`blocks(text)` finds them); `tests/reports/test_readme_table.py` keeps every one equal to it.
"""
from __future__ import annotations

import json
import re
import sys
from pathlib import Path

MAKE = "python -m lagbench.reports.readme_table"
END = "<!-- end of the claims table -->"
_BEGIN = re.compile(r"<!-- claims table: made by `" + re.escape(MAKE) + r" ([^`]+)`; do not edit by hand -->")


def begin(folder) -> str:
    """The marker a block made from `folder` (a path relative to the project's root) opens with."""
    return f"<!-- claims table: made by `{MAKE} {Path(folder).as_posix()}`; do not edit by hand -->"


def blocks(text: str) -> list[tuple[str, str]]:
    """(folder, block) of every claims table in `text`, markers included, in order."""
    out = []
    for m in _BEGIN.finditer(text):
        end = text.find(END, m.end())
        out.append((m.group(1), text[m.start():end + len(END) if end >= 0 else len(text)]))
    return out


FRAMEWORKS = (("jax", "JAX"), ("torch", "PyTorch"))


def _num(v) -> str:
    if v is None:
        return "–"
    v = float(v)
    return f"{v:.3g}" if 1e-3 <= abs(v) < 1e4 or v == 0 else f"{v:.2e}"


def _key_number(claim: dict, v: dict) -> str:
    key, values = claim.get("key"), v.get("values") or {}
    got = [f"{name} {_num((values.get(fw) or {}).get(key, {}).get('mean'))}" for fw, name in FRAMEWORKS
           if key in (values.get(fw) or {})]
    return f"{key} {claim.get('metric')}: " + ", ".join(got) if got else "not run"


def _published(claim: dict) -> str:
    p = (claim.get("published") or {}).get(claim.get("key"))
    if not isinstance(p, dict) or p.get("value") is None:
        return "none"
    return f"{_num(p['value'])} ({p.get('kind', '?')}{', other data' if p.get('other_data') else ''})"


def _parts(v: dict) -> str:
    parts = [p for p in v.get("parts") or [] if not p.get("check")]
    return "; ".join(f"{p['name']}: {p['verdict']}" for p in parts) or "–"


def _seeds(claims: list[dict], by_id: dict) -> str:
    """"seeds from 1000: 3 a model (8 in claims 6, 7; 1 in claim 5)": the usual count, then the others."""
    counts = {c.get("number"): len(by_id.get(c["id"], {}).get("seeds") or []) for c in claims}
    counts = {k: n for k, n in counts.items() if n}
    if not counts:
        return "no seeds ran"
    first = min(s for v in by_id.values() for s in v.get("seeds") or [])
    usual = max(set(counts.values()), key=lambda n: (list(counts.values()).count(n), n))
    other = {}
    for k, n in sorted(counts.items()):
        if n != usual:
            other.setdefault(n, []).append(str(k))
    rest = "; ".join(f"{n} in claim{'s' if len(ks) > 1 else ''} {', '.join(ks)}" for n, ks in sorted(other.items()))
    return f"seeds from {first}: {usual} a model" + (f" ({rest})" if rest else "")


def _seed_rule(claims: list[dict], profile) -> str:
    """The seed rule of the first paper claim that reads each seed as a replication (claims.json), if recorded."""
    rule = next((c["seed_rule"].get(profile) for c in claims if c.get("kind", "claim") == "claim"
                 and not c.get("pooled") and (c.get("seed_rule") or {}).get(profile)), None)
    return f" Seeds: {rule}." if rule else ""


def table(claims: list[dict], verdicts: dict) -> str:
    by_id = {v["id"]: v for v in verdicts.get("claims") or []}
    split = verdicts.get("split", "dev")
    profile = verdicts.get("profile")
    lines = [f"Profile `{profile}`, {split} split; {_seeds(claims, by_id)}.{_seed_rule(claims, profile)}", "",
             "| # | claim | paper | verdict | parts | key number (seed mean) | published |",
             "|---|---|---|---|---|---|---|"]
    ordered = sorted(claims, key=lambda c: (c.get("kind", "claim") != "claim", c.get("number", 0)))
    for c in ordered:
        v = by_id.get(c["id"], {})
        number = f"{c.get('number')}" + (" (check)" if c.get("kind") == "check" else "")
        lines.append(f"| {number} | {c.get('title')} | {c.get('paper')} {c.get('section')} | "
                     f"{v.get('verdict', 'not run')} | {_parts(v)} | {_key_number(c, v)} | {_published(c)} |")
    variants = [f"- claim {c.get('number')}, variant \"{x['name']}\": {x['verdict']}"
                for c in ordered for x in by_id.get(c["id"], {}).get("variants") or []]
    if variants:
        lines += ["", "Variants (a departure from the paper; never the claim's verdict):", *variants]
    return "\n".join(lines)


def read(folder) -> tuple[list[dict], dict]:
    folder = Path(folder)
    verdicts = folder / "verdicts.json"
    if not verdicts.is_file():
        verdicts = folder / "summary" / "verdicts.json"
    return json.loads((folder / "claims.json").read_text())["claims"], json.loads(verdicts.read_text())


def block(folder, root=None) -> str:
    """The claims table of `folder` between its markers; `root`: the folder the path is relative to."""
    return f"{begin(folder)}\n{table(*read(Path(root or '.') / folder))}\n{END}"


if __name__ == "__main__":
    if len(sys.argv) != 2:
        raise SystemExit("usage: python -m lagbench.reports.readme_table FOLDER (a results or sample-report folder)")
    print(block(sys.argv[1]))
