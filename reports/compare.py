"""Comparison tables: cross-framework agreement and the cheapest model reaching the best error.

``cross_framework_table`` compares every framework with the first one (per claim and model: means,
relative difference of means, the largest per-seed difference over seeds run in both, and beside them
the seed spread for scale: the larger of the two frameworks' seed standard deviations; "yes" in
"beyond spread" flags a difference of means larger than that spread; "non-finite seeds" counts the seeds
whose metric is inf or NaN, e.g. a diverged rollout, left out of the means and per-seed differences).
The report's section around it: ``reports.sections_frameworks``.
``cheapest_table`` picks, per claim, among (framework, model) whose mean claim metric is within
``tolerance`` x the best (lowest) mean, the one with the highest training throughput
(``train_samples_per_s``; else the shortest ``train_time_s``), counting only models that passed their
competence bar (a claim with bars: a model without a passed bar is left out, so a model that learned
nothing is never recommended); a pooled claim (its metric a share of seeds, higher is better) is
skipped. ``bench_cheapest_table`` does the same per system from ``bench/inference.csv`` (error vs
``samples_per_s``).
"""

from __future__ import annotations

import math

import pandas as pd

from lagbench.reports.document import NOT_RUN
from lagbench.reports.fmt import num, summarise
from lagbench.reports.load import Results
from lagbench.reports.tables import claim_models, values

TOLERANCE = 2.0


def cross_framework_table(res: Results) -> pd.DataFrame | None:
    fws = res.frameworks
    if len(fws) < 2:
        return None
    ref, rows = fws[0], []
    for claim in res.claims:
        metric = claim.get("metric")
        vals = values(res.claim_units(claim["id"]), metric)
        for model in claim_models(res, claim):
            for fw in fws[1:]:
                a, b = vals.get(ref, {}).get(model), vals.get(fw, {}).get(model)
                by_seed = {}
                for u in res.usable(claim["id"]):
                    if u.model == model and u.framework in (ref, fw) and metric:
                        by_seed.setdefault(u.seed, {})[u.framework] = u.metric(metric)
                paired = [abs(d[ref] - d[fw]) for d in by_seed.values()
                          if d.get(ref) is not None and d.get(fw) is not None]
                diffs = [x for x in paired if math.isfinite(x)]
                bad = {f: sum(d.get(f) is not None and not math.isfinite(d[f]) for d in by_seed.values())
                       for f in (ref, fw)}
                rel = NOT_RUN
                if a and b:
                    scale = max(abs(a["mean"]), abs(b["mean"]))
                    rel = num(abs(a["mean"] - b["mean"]) / scale) if scale > 0 else "0"
                spread = max((s["std"] for s in (a, b) if s and s["n"] > 1 and math.isfinite(s["std"])),
                             default=None)
                beyond = NOT_RUN
                if a and b and spread is not None:
                    beyond = "yes" if abs(a["mean"] - b["mean"]) > spread else "no"
                rows.append({
                    "claim": claim["id"], "model": model, "metric": metric or "unknown",
                    ref: num(a["mean"]) if a else NOT_RUN, fw: num(b["mean"]) if b else NOT_RUN,
                    "rel. diff of means": rel,
                    "max per-seed abs. diff": num(max(diffs)) if diffs else NOT_RUN,
                    "seed spread (std)": num(spread) if spread is not None else NOT_RUN,
                    "beyond spread": beyond,
                    "seeds in both": str(len(paired)),
                    "non-finite seeds": ", ".join(f"{f} {n}" for f, n in bad.items()) if any(bad.values()) else "none",
                })
    return pd.DataFrame(rows) if rows else None


def _cost(units) -> tuple[str, float] | None:
    """('samples/s', value) (higher is cheaper) or ('train s', value) (lower is cheaper)."""
    thr = summarise([u.result.get("train_samples_per_s") for u in units
                     if isinstance(u.result.get("train_samples_per_s"), int | float)])
    if thr["n"]:
        return "samples/s", thr["mean"]
    t = summarise([u.result.get("train_time_s") for u in units if isinstance(u.result.get("train_time_s"), int | float)])
    return ("train s", t["mean"]) if t["n"] else None


def _competent(res: Results, cid: str):
    """(framework, model) -> passed its bar; None when the claim has no bars (every model counts)."""
    comp = (res.verdicts.get(cid) or {}).get("competence") or {}
    if not any(comp.values()):
        return None
    return {(fw, m) for fw, per in comp.items() for m, r in (per or {}).items() if r.get("passed")}


def cheapest_table(res: Results, tolerance: float = TOLERANCE) -> pd.DataFrame | None:
    rows = []
    for claim in res.claims:
        if claim.get("pooled"):   # a share over seeds (higher is better), not an error to minimise
            continue
        metric, units = claim.get("metric"), res.usable(claim["id"])
        vals = values(units, metric)
        competent = _competent(res, claim["id"])
        cands = []
        for fw, per in vals.items():
            for model, s in per.items():
                if competent is not None and (fw, model) not in competent:
                    continue
                cost = _cost([u for u in units if u.framework == fw and u.model == model])
                cands.append((s["mean"], fw, model, cost))
        finite = [c for c in cands if math.isfinite(c[0])]
        if not finite:
            continue
        best = min(finite, key=lambda c: c[0])
        ok = [c for c in finite if c[0] <= best[0] * tolerance or c[0] == best[0]]
        with_cost = [c for c in ok if c[3] is not None]
        if with_cost:
            pick = max(with_cost, key=lambda c: c[3][1] if c[3][0] == "samples/s" else -c[3][1])
        else:
            pick = best
        rows.append({
            "claim": claim["id"], "system": str(claim.get("system", "unknown")), "metric": metric,
            "best": f"{best[2]} ({best[1]}): {num(best[0])}",
            "cheapest within tolerance": f"{pick[2]} ({pick[1]}): {num(pick[0])}",
            "its cost": f"{num(pick[3][1])} {pick[3][0]}" if pick[3] else "not recorded",
        })
    return pd.DataFrame(rows) if rows else None


def _fastest(df: pd.DataFrame, keys: list[str]) -> pd.Series:
    """samples_per_s of the fastest row (any mode, any threads) per key."""
    df = df.assign(samples_per_s=pd.to_numeric(df["samples_per_s"], errors="coerce"))
    return df.groupby(keys)["samples_per_s"].max()


def gpu_vs_cpu_table(res: Results, batches=(1, 4096)) -> pd.DataFrame | None:
    """Inference throughput per (system, model, formulation, dtype, batch in `batches`) and framework on the
    speed study's CPU (bench/) and GPU (bench_gpu/) machines, each framework's fastest mode, and GPU / CPU.
    Only the operations both runs measured; None when either run is missing."""
    cpu, gpu = res.bench.get("inference"), res.bench_gpu.get("inference")
    if cpu is None or gpu is None:
        return None
    keys = ["system", "model", "formulation", "framework", "dtype", "batch"]
    both = pd.concat({"cpu": _fastest(cpu, keys), "gpu": _fastest(gpu, keys)}, axis=1).dropna()
    both = both[both.index.get_level_values("batch").isin(batches)]
    if both.empty:
        return None
    rows = [{"system": k[0], "model": f"{k[1]}/{k[2]}", "framework": k[3], "dtype": k[4], "batch": int(k[5]),
             "CPU samples/s": num(r["cpu"]), "GPU samples/s": num(r["gpu"]), "GPU / CPU": num(r["gpu"] / r["cpu"])}
            for k, r in both.iterrows()]
    return pd.DataFrame(rows)


def bench_cheapest_table(res: Results, tolerance: float = TOLERANCE, gpu: bool = False) -> pd.DataFrame | None:
    """Per system: the lowest inference error and the fastest row within `tolerance` of it (bench/, or
    bench_gpu/ with gpu=True)."""
    df = (res.bench_gpu if gpu else res.bench).get("inference")
    if df is None or df.empty:
        return None
    df = df[pd.to_numeric(df["error"], errors="coerce").notna()].copy()
    df["error"] = df["error"].astype(float)
    df["samples_per_s"] = pd.to_numeric(df["samples_per_s"], errors="coerce")
    rows = []
    for system, g in df.groupby("system", sort=True):
        best = g.loc[g["error"].idxmin()]
        ok = g[g["error"] <= best["error"] * tolerance].dropna(subset=["samples_per_s"])
        pick = ok.loc[ok["samples_per_s"].idxmax()] if len(ok) else best

        def name(r):
            mode = f"/{r['mode']}" if r.get("mode") in ("aoti", "traced") else ""
            return f"{r['model']}/{r['formulation']} ({r['framework']}{mode}, {r['dtype']})"

        rows.append({"system": str(system), "best error": f"{name(best)}: {num(best['error'])}",
                     "cheapest within tolerance": f"{name(pick)}: {num(pick['error'])}",
                     "samples/s": num(pick["samples_per_s"])})
    return pd.DataFrame(rows) if rows else None
