"""The Findings section: where the papers and their original code disagree (the data:
``replication/claims/findings.py``).

The paper profile runs the code's protocol; quick and full run the suite's efficient protocols (each
finding's 'what it changes' says how). For each finding this module reports which one was run, read from the usable units' ``protocol`` and
``model_spec`` (any of the finding's ``keys``, searched in nested dicts, plus a generic ``variant``),
restricted to units of claims whose ``system`` contains one of ``systems`` (all systems if empty).
"""

from __future__ import annotations

import pandas as pd

from lagbench.replication.claims.findings import FINDINGS, Finding
from lagbench.reports.document import NOT_RUN, Para, Section, Table
from lagbench.reports.fmt import plain
from lagbench.reports.load import Results


def _lookup(d, keys: set[str], prefix: str = "") -> dict[str, str]:
    out = {}
    if isinstance(d, dict):
        for k, v in d.items():
            name = f"{prefix}{k}"
            if str(k).lower() in keys:   # a record (a protocol part) as its fields in one line
                out[name] = plain({a: b for a, b in v.items() if b is not None} if isinstance(v, dict) else v)
            else:
                out.update(_lookup(v, keys, name + "."))
    return out


def what_ran(res: Results, f: Finding) -> str:
    claims = [c for c in res.claims if not f.systems or any(
        s in str(c.get("system", "")).lower() for s in f.systems)]
    units = [u for c in claims for u in res.usable(c["id"])]
    if not units:
        return NOT_RUN
    keys = {k.lower() for k in f.keys} | {"variant"}
    seen: dict[str, set[str]] = {}
    for u in units:
        for src in ("protocol", "model_spec"):
            for k, v in _lookup(u.result.get(src), keys).items():
                seen.setdefault(f"{src}.{k}", set()).add(v)
    if not seen:
        return "not recorded in result files"
    return "; ".join(f"{k}: {' / '.join(sorted(v)[:4])}" for k, v in sorted(seen.items())[:4])


def findings_sections(res: Results) -> list[Section]:
    rows = [{"#": str(i), "finding": f.title, "paper": f.paper, "original code": f.code, "run here": what_ran(res, f),
             "what it changes": f.changes} for i, f in enumerate(FINDINGS, 1)]
    s = Section("Findings: paper against original code")
    profile = (res.run or {}).get("profile") or res.verdict_profile or "unknown"
    s.add(Para("Where the LNN paper and its original code (MilesCranmer/lagrangian_nns) disagree. The paper "
               "profile runs the code's protocol at the code's scales; quick and full run the suite's efficient "
               "protocols at smaller scales, as 'what it changes' says. 'run here' is read from the protocol and "
               f"model spec recorded in each unit's result.json of this run (profile: {profile})."))
    s.add(Table("Paper against code", pd.DataFrame(rows),
                ["shared/reference/lnn_original_code.md §9", "units/*/*/*/seed*/result.json (protocol, model_spec)"]))
    return [s]
