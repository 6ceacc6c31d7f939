"""The report's cross-framework section: JAX against PyTorch per claim and model, from the result files.

``frameworks_sections(res) -> [Section("Cross-framework agreement")]`` holds, for every framework against the
first one (``res.frameworks[0]``):
  1. the claim's metric per framework (``compare.cross_framework_table``: means, relative difference, the
     largest per-seed difference, the seed spread beside them for scale, "beyond spread" flagged), and the
     flagged rows listed under it (also a paired seed beyond the spread, and non-finite seeds in one only);
  2. the verdict judged on each framework's units alone (``res.verdicts[claim]["by_framework"]``);
  3. the training curves of paired units (same claim, model and seed: the same initial weights and batches,
     `replication.training.protocol`), from ``train_log.csv``: the relative difference of the first logged loss
     (the same weights: rounding only; above ``START_TOL`` flagged, the frameworks compute different
     losses), the first logged step from which the losses stay parted by more than ``PART`` (float32
     training of a chaotic model parts legitimately, `tests/replication/training/test_training_parity.py`), the
     relative difference of the last logged loss, and whether restarts chose the same initialisation;
  4. JAX against PyTorch speed per operation (``bench/ratios.csv``), where the speed study ran.
Reads only the result files (no ML framework).
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from lagbench.reports.compare import cross_framework_table
from lagbench.reports.document import NOT_RUN, Bullets, Para, Section, Table
from lagbench.reports.fmt import cell, num
from lagbench.reports.load import Results, Unit
from lagbench.reports.sections_speed import _bench_table
from lagbench.reports.tables import claim_models

START_TOL = 1e-4   # relative difference of the first logged training loss from identical weights
PART = 1e-2        # relative difference of the training losses from which two curves count as parted


def _rel(a: float, b: float) -> float:
    if not (math.isfinite(a) and math.isfinite(b)):
        return 0.0 if a == b else math.inf
    scale = max(abs(a), abs(b))
    return abs(a - b) / scale if scale > 0 else 0.0


def curve_agreement(a: pd.DataFrame | None, b: pd.DataFrame | None) -> dict | None:
    """Two train logs (step, loss) compared at their common logged steps: {start, parted_at (None: never),
    end, steps (the last common step), n (common steps)}; None when they share no step."""
    if a is None or b is None or not {"step", "loss"} <= set(a.columns) & set(b.columns):
        return None
    both = pd.merge(a[["step", "loss"]], b[["step", "loss"]], on="step", suffixes=("_a", "_b"))
    both = both.apply(pd.to_numeric, errors="coerce").dropna(subset=["step"]).sort_values("step")
    if both.empty:
        return None
    rel = np.array([_rel(x, y) for x, y in zip(both["loss_a"], both["loss_b"], strict=True)])
    apart = rel > PART
    # the first step after which every logged step is apart (a curve that parts and rejoins is not parted)
    together = np.flatnonzero(~apart)
    first = 0 if not together.size else int(together[-1]) + 1
    parted = None if first >= len(rel) else int(both["step"].iloc[first])
    return {"start": float(rel[0]), "parted_at": parted, "end": float(rel[-1]),
            "steps": int(both["step"].iloc[-1]), "n": len(rel)}


def _chosen(u: Unit):
    sc = u.result.get("scouting")
    return sc.get("chosen") if isinstance(sc, dict) else None


def training_curves_table(res: Results) -> pd.DataFrame | None:
    """One row per (claim, model, framework against the first) with paired seeds: see the module doc."""
    fws = res.frameworks
    if len(fws) < 2:
        return None
    ref, rows = fws[0], []
    for claim in res.claims:
        by_key: dict = {}
        for u in res.usable(claim["id"]):
            by_key.setdefault((u.model, u.seed), {})[u.framework] = u
        for model in claim_models(res, claim):
            for fw in fws[1:]:
                pairs = [(d[ref], d[fw]) for (m, _), d in sorted(by_key.items()) if m == model and ref in d and fw in d]
                found = [(c, ua, ub) for ua, ub in pairs
                         if (c := curve_agreement(ua.table("train_log.csv"), ub.table("train_log.csv")))]
                if not found:
                    continue
                starts = [c["start"] for c, _, _ in found]
                parted = [c["parted_at"] for c, _, _ in found]
                scouted = [(_chosen(ua), _chosen(ub)) for _, ua, ub in found if _chosen(ua) is not None]
                rows.append({
                    "claim": claim["id"], "model": model, "frameworks": f"{ref} / {fw}", "seeds": str(len(found)),
                    "first loss rel. diff (max)": num(max(starts)),
                    "start differs": "yes" if max(starts) > START_TOL else "no",
                    "parted at step": ", ".join("never" if p is None else str(p) for p in parted),
                    "last logged step": ", ".join(str(c["steps"]) for c, _, _ in found),
                    "last loss rel. diff (max)": num(max(c["end"] for c, _, _ in found)),
                    "restarts chose alike": ("-" if not scouted else
                                             "yes" if all(a == b for a, b in scouted) else "no"),
                })
    return pd.DataFrame(rows) if rows else None


def _number(text) -> float | None:
    try:
        return float(text)
    except (TypeError, ValueError):
        return None


def _flag(r) -> str:
    """What a row of the claim-metric table flags ("" for nothing): the difference of means beyond the seed
    spread; a paired seed (same weights, same batches) whose two frameworks differ by more than the spread
    (training parted, see the curves table); non-finite seeds in one framework and not as many in the other."""
    counts = [int(x.rsplit(" ", 1)[1]) for x in str(r.get("non-finite seeds", "none")).split(", ") if x != "none"]
    why = []
    if r["beyond spread"] == "yes":
        why.append(f"difference of means beyond the seed spread (relative {r['rel. diff of means']}, "
                   f"spread {r['seed spread (std)']})")
    paired, spread = _number(r["max per-seed abs. diff"]), _number(r["seed spread (std)"])
    if paired is not None and spread is not None and paired > spread:
        why.append(f"a paired seed differs by {r['max per-seed abs. diff']}, more than the seed spread "
                   f"{r['seed spread (std)']} (see the training curves of paired units)")
    if len(set(counts)) > 1:
        why.append(f"non-finite seeds differ ({r['non-finite seeds']})")
    return f"{r['claim']} / {r['model']} ({r['metric']}): " + "; ".join(why) if why else ""


def verdicts_table(res: Results) -> pd.DataFrame | None:
    """Per claim run in two frameworks or more: the verdict judged on each framework's units alone."""
    fws, rows = res.frameworks, []
    for claim in res.claims:
        by_fw = (res.verdicts.get(claim["id"]) or {}).get("by_framework") or {}
        if not isinstance(by_fw, dict) or len(by_fw) < 2:
            continue
        row = {"claim": claim["id"]}
        row.update({fw: cell(by_fw.get(fw)) for fw in fws})
        row["same"] = "yes" if len({str(v) for v in by_fw.values()}) == 1 else "no"
        parts = (res.verdicts.get(claim["id"]) or {}).get("parts") or []
        row["parts that disagree (a defect)"] = ", ".join(p["name"] for p in parts if p.get("flag")) or "none"
        rows.append(row)
    return pd.DataFrame(rows) if rows else None


CLAIM_NOTE = ("'beyond spread': the difference of the means is larger than the seed spread (the larger of "
              "the two frameworks' seed standard deviations); 'not run' where a framework has fewer than "
              "two seeds. Non-finite values (a diverged rollout) are left out of the means and counted apart.")
CURVES_NOTE = (f"Paired units start from the same weights and see the same batches. 'start differs': the "
               f"first logged training losses differ by more than {START_TOL:g} (relative), more than rounding "
               f"explains. 'parted at step': the first logged step from which the losses stay more than "
               f"{PART:g} apart, per seed ('never': together at the last logged step). float32 training of an LNN "
               "whose learned Hessian is near-singular on some batches parts legitimately: in the parity tests "
               "the double-pendulum LNN's parameters part after about 80 steps and the relativistic smoke "
               "LNN's after 14, while the same runs in float64 stay 1e-8 apart or closer. Restarts: the "
               "continuation's log only.")


def frameworks_sections(res: Results) -> list[Section]:
    s = Section("Cross-framework agreement")
    fws = res.frameworks
    table = cross_framework_table(res)
    if table is None:
        s.add(Para(f"Comparison across frameworks: {NOT_RUN} (frameworks found: "
                   f"{', '.join(fws) if fws else 'none'})."))
    else:
        s.add(Para(f"Each framework against {fws[0]}: the same protocol, initial parameters and batch order, "
                   "so differences come from floating-point order of operations and library kernels. The seed "
                   "spread is there for scale: a difference beyond it ('beyond spread': yes) is larger than the "
                   "variation between seeds of one framework, which float32 chaos alone rarely explains."))
        s.add(Table("Claim metric per framework", table, ["units/*/*/*/seed*/result.json"], note=CLAIM_NOTE))
        flags = [_flag(r) for _, r in table.iterrows()]
        s.add(Bullets([f for f in flags if f]) if any(flags) else
              Para("No claim metric differs between frameworks by more than its seed spread, for the means or "
                   "for any paired seed, and no framework has more non-finite seeds than the other."))
    verdicts = verdicts_table(res)
    if verdicts is not None:
        s.add(Table("Verdict per framework", verdicts, ["units/*/*/*/seed*/result.json"],
                    note="Each framework's units judged alone by the claim's rule (`replication.claims.verdicts`)."))
    curves = training_curves_table(res)
    if curves is not None:
        s.add(Table("Training curves of paired units", curves, ["units/*/*/*/seed*/train_log.csv"],
                    note=CURVES_NOTE))
    if "ratios" in res.bench:
        s.add(Table("JAX against PyTorch speed per operation", _bench_table(res.bench["ratios"]),
                    ["bench/ratios.csv"]))
    return [s]
