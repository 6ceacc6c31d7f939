"""Environment section (run.json, unit versions/hardware/commits, bench/machine.json) and the closing
appendix: the index of tables and figures (each with its number, its section and the result files its
numbers come from) and every unit file.
"""

from __future__ import annotations

import datetime as dt

import pandas as pd

from lagbench.reports.document import NOT_RUN, Figure, Para, Section, Table
from lagbench.reports.fmt import cell, plain
from lagbench.reports.load import Results
from lagbench.reports.sections_fit import is_fit_results


def flatten(d, prefix: str = "") -> dict[str, str]:
    out = {}
    if isinstance(d, dict):
        for k, v in d.items():
            out.update(flatten(v, f"{prefix}{k}."))
    elif isinstance(d, list | tuple):
        out[prefix.rstrip(".")] = plain(d)
    else:
        out[prefix.rstrip(".")] = cell(d, "none")
    return out


def _kv(d: dict, source: str) -> pd.DataFrame:
    return pd.DataFrame([{"field": k, "value": v, "file": source} for k, v in flatten(d).items()])


def environment_sections(res: Results, now: dt.datetime | None = None) -> list[Section]:
    now = now or dt.datetime.now(dt.UTC)
    s = Section("Environment")
    s.add(Para(f"Report generated {now.strftime('%Y-%m-%d %H:%M UTC')} from {res.root.as_posix()}."))
    run = res.run
    fits = is_fit_results(res)
    if run is None and not fits:   # a fit or evaluate folder has no run manifest, and never had
        s.add(Para(f"Run manifest (run.json): {NOT_RUN}."))
    elif run is not None:
        s.add(Table("Run manifest", _kv(run, "run.json"), ["run.json"]))
    usable = res.usable()
    if usable:
        rows = []
        for key in ("versions", "hardware"):
            combos = {}
            for u in usable:
                for k, v in flatten(u.result.get(key) or {}).items():
                    combos.setdefault(f"{key}.{k}", set()).add(v)
            rows += [{"field": k, "values in units": "; ".join(sorted(v))} for k, v in combos.items()]
        for key in ("commit", "dtype") if fits else ("commit", "profile", "dtype"):   # a fit runs under no profile
            vals = sorted({cell(u.result.get(key), "none") for u in usable})
            rows.append({"field": key, "values in units": "; ".join(vals)})
        created = sorted(str(u.result.get("created")) for u in usable if u.result.get("created"))
        if created:
            rows.append({"field": "created (first – last)", "values in units": f"{created[0]} – {created[-1]}"})
        s.add(Table("Versions, hardware and commits recorded by the units", pd.DataFrame(rows),
                    ["units/*/*/*/seed*/result.json"]))
    else:
        s.add(Para(f"Unit environment: {NOT_RUN} (no usable unit)."))
    if res.machine is not None:
        s.add(Table("Speed-study machine", _kv(res.machine, "bench/machine.json"), ["bench/machine.json"]))
    return [s]


INDEX = "Appendix: index of tables and figures"


def sources_sections(res: Results, sections: list[Section]) -> list[Section]:
    rows = []
    for sec in sections:
        for b in sec.blocks:
            if isinstance(b, Table | Figure):
                kind = "Table" if isinstance(b, Table) else "Figure"
                name = b.title if isinstance(b, Table) else b.caption
                rows.append({"number": f"{kind} {b.number}" if b.number else kind.lower(),
                             "title": name if len(name) <= 90 else name[:89].rsplit(" ", 1)[0] + " …",
                             "section": sec.title, "from files": "; ".join(b.sources) or "computed"})
    s = Section(INDEX)
    s.add(Para("Every table and figure by its number, with its section and the result files its numbers come "
               "from (paths relative to the results folder; <framework>/<model>/seed<k> expand to the units "
               "listed below)."))
    s.add(Table("Tables and figures", pd.DataFrame(rows) if rows else pd.DataFrame({"number": [NOT_RUN]})))
    units = [{"unit": u.rel, "status": u.status,
              "checksum": str(u.result.get("checksum", "none"))[:12],
              "files": ", ".join(sorted((u.result.get("files") or {}).keys())) or "none"} for u in res.units]
    s.add(Table("Unit files", pd.DataFrame(units) if units else pd.DataFrame({"unit": [NOT_RUN]}),
                ["units/*/*/*/seed*/result.json"]))
    return [s]
