"""Read and validate a results folder (layout in ``docs/RESULTS.md``); never raises on bad data.

``load_results(root) -> Results``. Every unit folder ``units/<claim>/<framework>/<model>/seed<k>/`` with a
``result.json`` becomes a :class:`Unit` whose ``status`` is ``"ok"``, ``"failed"`` (the runner's own
verdict) or ``"corrupt"`` (unreadable JSON, wrong schema, path mismatch, checksum or listed-file sha256
mismatch; see :mod:`reports.integrity`). Only ``ok`` units feed numbers into the report. Missing files
leave ``None``/empty fields; problems are collected as human-readable strings in ``Results.problems``.

Verdicts are recomputed from the verified units by ``replication.claims.verdicts.judge`` (the function the
runner uses; it imports no framework and no training code), so a deleted or corrupted unit never leaves
a stale verdict; ``summary/verdicts.json`` is only compared with them. The claims are those the runs into
the folder asked for (run.json's "claims", ``asked_claims``) and any other with units there, so that a
two-claim run's report speaks of two claims. ``run.json``'s planned units
that have no result are listed in ``Results.planned_missing``, and ``Results.unfinished`` is true when
the run has not recorded its end.

The pieces: the types ``Unit`` and ``Results`` (``reports.loaded``, re-exported here), one file or unit folder
read (``reports.folder_files``), the speed study's tables (``reports.bench_tables``; ``BENCH_COLUMNS``
re-exported here).
"""

from __future__ import annotations

import json
from pathlib import Path

import pandas as pd

from lagbench.reports.bench_tables import BENCH_COLUMNS, load_bench
from lagbench.reports.folder_files import load_unit, read_json, seed_key
from lagbench.reports.loaded import Results, Unit, protocol_of

__all__ = ["BENCH_COLUMNS", "Results", "Unit", "asked_claims", "load_results", "protocol_of"]


def asked_claims(root: Path, run: dict | None = None, earlier: bool = True) -> set[str] | None:
    """The claims `lagbench run` was asked for in `root`: the "claims" of its run.json (`run`, read from `root`
    when not given) and, with `earlier`, of every earlier invocation's record (runs/run-*.json); None where
    run.json records none (an older run, or a folder of another command): then every claim is the folder's."""
    root = Path(root)
    run = run if run is not None else read_json(root / "run.json", [], root)
    if not isinstance((run or {}).get("claims"), list):
        return None
    asked = {c for c in run["claims"] if isinstance(c, str)}
    for path in sorted((root / "runs").glob("run-*.json")) if earlier else ():
        try:
            earlier = json.loads(path.read_text(encoding="utf-8")).get("claims")
        except (ValueError, OSError, AttributeError):
            continue
        asked |= {c for c in earlier if isinstance(c, str)} if isinstance(earlier, list) else set()
    return asked


def _catalogue(res: Results, claims_json: dict | None) -> list[dict]:
    """The claims of the report: claims.json's that the runs into the folder asked for (`asked_claims`), and
    any other that has units there."""
    claims = []
    if claims_json is not None:
        raw = claims_json.get("claims")
        if isinstance(raw, list):
            claims = [c for c in raw if isinstance(c, dict) and isinstance(c.get("id"), str)]
        else:
            res.problems.append("claims.json has no 'claims' list")
    asked = asked_claims(res.root, res.run)
    if asked is not None:
        claims = [c for c in claims if c["id"] in asked | {u.claim for u in res.units}]
    known = {c["id"] for c in claims}
    extra = sorted(({u.claim for u in res.units} | set(res.verdicts)) - known)
    claims += [{"id": cid, "title": "(not in claims.json)"} for cid in extra]
    return sorted(claims, key=lambda c: (c.get("number") if isinstance(c.get("number"), int) else 1 << 30, c["id"]))


def load_results(root: str | Path) -> Results:
    """Read everything under ``root``; a missing or empty folder gives an empty :class:`Results`."""
    root = Path(root)
    res = Results(root=root)
    if not root.is_dir():
        res.problems.append(f"results folder {root} does not exist")
        return res
    res.run = read_json(root / "run.json", res.problems, root)
    claims_json = read_json(root / "claims.json", res.problems, root)
    verdicts = read_json(root / "summary" / "verdicts.json", res.problems, root) or {}
    res.verdict_profile = verdicts.get("profile")
    res.verdict_split = verdicts.get("split")
    res.split = (res.run or {}).get("split") or res.verdict_split or "dev"
    for v in verdicts.get("claims") or []:
        if isinstance(v, dict) and isinstance(v.get("id"), str):
            res.stored_verdicts[v["id"]] = v
    units_dir = root / "units"
    if units_dir.is_dir():
        # results superseded by a later protocol (folders "superseded-<time>-seed<k>") are history, not units
        found = [load_unit(root, p) for p in sorted(units_dir.rglob("result.json"))
                 if not p.parent.name.startswith("superseded-")]
        mine = [u for u in found if not u.result or (u.result.get("split") or "dev") == res.split]
        if len(mine) < len(found):   # one split a report: the other's seeds are neither shown nor judged
            res.problems.append(f"{len(found) - len(mine)} unit(s) of another split than this run's ({res.split}) "
                                f"are in this folder and left out of this report")
        found = mine
        res.units = sorted(found, key=lambda u: (u.claim, u.framework, u.model, seed_key(u.seed)))
    csv_path = root / "summary" / "units.csv"
    if csv_path.is_file():
        try:
            res.units_csv = pd.read_csv(csv_path)
        except (ValueError, OSError) as exc:
            res.problems.append(f"summary/units.csv unreadable: {exc}")
    if res.units_csv is not None and {"claim", "framework", "model", "seed"} <= set(res.units_csv.columns):
        have = {(u.claim, u.framework, u.model, u.seed) for u in res.units}
        for row in res.units_csv.itertuples(index=False):
            key = (str(row.claim), str(row.framework), str(row.model), str(row.seed))
            if key not in have:
                res.listed_missing.append("units/{}/{}/{}/seed{}".format(*key))
    res.claims = _catalogue(res, claims_json)
    _recompute_verdicts(res)
    _check_plan(res)
    load_bench(res)
    return res


def _recompute_verdicts(res: Results) -> None:
    """Verdicts from the verified unit files, by the runner's own function; stored ones only compared."""
    from lagbench.replication.claims import CLAIMS, registration, tuned
    from lagbench.replication.claims.verdicts import frame, judge, of_split

    profile = (res.run or {}).get("profile") or res.verdict_profile
    df = of_split(frame([u.result for u in res.units if u.status in ("ok", "failed")]), res.split)
    ids = {c["id"] for c in res.claims} | {u.claim for u in res.units}
    committed, adopted = registration.registrations(), tuned.records()
    res.verdicts = {cid: judge(CLAIMS[cid], df, profile, committed, adopted) for cid in sorted(ids) if cid in CLAIMS}
    for cid, v in res.stored_verdicts.items():
        if cid in ids:
            res.verdicts.setdefault(cid, v)   # a claim this code no longer has: its recorded verdict
    stale = sorted(cid for cid, v in res.stored_verdicts.items()
                   if cid in CLAIMS and cid in ids and v.get("verdict") != res.verdicts[cid]["verdict"])
    if stale:
        res.problems.append("summary/verdicts.json disagrees with the unit files for " + ", ".join(stale)
                            + " (units changed since it was written, or it predates the current rules); "
                              "the verdicts shown are recomputed from the unit files")


def _check_plan(res: Results) -> None:
    run = res.run or {}
    planned = run.get("planned_units")
    if isinstance(planned, list):
        have = {f"{u.claim}/{u.framework}/{u.model}/seed{u.seed}" for u in res.units}
        res.planned_missing = [f"units/{p}" for p in planned if isinstance(p, str) and p not in have]
    res.unfinished = bool(run) and not run.get("finished")
