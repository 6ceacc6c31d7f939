"""`lagbench tune --claim ID`: every model of a claim searched alike on the development split.

`tune(claim, profile, n_configs, n_seeds, frameworks, out, progress, widths=None) -> ledger`: for each
configuration of `search.configs` (or, given `widths`, of the width sweep `search.sweep(widths)`; the same
list for every model), each trained model of the claim under `profile` is
trained with it on the development seeds (`splits.DEV`: seeds 0.., the development draws; never the test
split) and scored by its development held-out error: `heldout_l1` where the evaluation gives it, else the
claim's metric (lower is better), averaged over seeds and frameworks; a pooled claim (a pace study: claims 6
and 7) by its pace instead, the median over seeds of the samples to leave the plateau (+inf: never), as its
verdict reads pace over a sample of seeds (run it with the claim's seed count, one cohort). The units go to
OUT/config<k>/units/...; a rerun into the same OUT reads back the units already finished (a result of another
protocol is set aside and redone, as `lagbench run` does) and continues a training in flight from its
snapshot. The ledger goes to OUT/ledger.json and OUT/ledger.csv: per model and configuration
its knob values and score, and per model the configurations tried, the chosen one (the lowest score)
and the split they were scored on ("dev").
What it does not do: change a claim. A ledger's choices reach the claim only when adopted
(`python -m replication.tuning.adopt OUT/ledger.json`) and registered (a new dated line).
"""
from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import pandas as pd

from replication import results as R
from replication.claims import untuned
from replication.run import splits
from replication.run.executor import run_units
from replication.run.runner import is_current
from replication.run.units import Unit
from replication.tuning import search

PACE = "samples_to_leave"   # a pooled claim's score: training samples until the plateau is left (+inf: never)


def score_metric(result: dict, claim) -> float | None:
    m = result.get("metrics") or {}
    if claim.pooled:   # a pace study decides by pace, so its search is scored by pace (never leaving: +inf)
        v = m.get(PACE)
        return float(v) if isinstance(v, int | float) and not math.isnan(v) else None
    v = m.get("heldout_l1", m.get(claim.metric))
    return float(v) if isinstance(v, int | float) and math.isfinite(v) else None


def scored_by(claim) -> str:
    return (f"median {PACE} over the seeds (+inf: never left)" if claim.pooled
            else f"mean over seeds of heldout_l1 (else {claim.metric})")


@R.writes
def tune(claim_id: str, profile: str = "quick", n_configs: int = 4, n_seeds: int = 1, frameworks=("jax",),
         out="results/tune", progress: bool = True, widths=None) -> dict:
    claim = untuned(claim_id)   # the search is around the claim as written, never around an adopted choice
    if isinstance(n_seeds, bool) or not isinstance(n_seeds, int) or not 1 <= n_seeds <= splits.SEEDS_PER_SPLIT:
        raise ValueError(f"--seeds: {n_seeds!r} is not valid; expected an integer from 1 to {splits.SEEDS_PER_SPLIT}")
    grid = search.sweep(widths) if widths else search.configs(n_configs)
    labels = [e.label for e in claim.models if e.runs_in(profile) and e.train]
    if not labels:
        raise ValueError(f"--claim {claim_id}: trains no model under profile {profile!r}")
    out = R.output_folder(out, "--out")
    base = claim.protocol(profile)
    rows = []
    for k, knobs in enumerate(grid):
        models = tuple(search.apply(e, base, profile, knobs) if e.label in labels else e for e in claim.models)
        variant = dataclasses.replace(claim, models=models)
        units = [Unit(variant, e, fw, seed, profile) for e in models if e.label in labels for fw in frameworks
                 for seed in splits.DEV.seeds(n_seeds)]
        folder = out / f"config{k}"
        todo = [u for u in units if not is_current(u, folder)]   # a rerun resumes: finished units are read back
        if todo:
            run_units(todo, folder, profile, progress, jobs=1)
        for u in units:
            try:
                r = R.load_result(u.folder(folder))
            except R.CorruptResult:
                r = {}
            rows.append({"model": u.entry.label, "config": k, **{f"knob_{n}": v for n, v in knobs.items()},
                         "framework": u.framework, "seed": u.seed, "split": u.split, "status": r.get("status"),
                         "score": score_metric(r, claim) if r.get("status") == "ok" else None})
    df = pd.DataFrame(rows)
    R.write_csv(out / "ledger.csv", df)
    ledger = {"schema": R.SCHEMA, "claim": claim.id, "profile": profile, "split": "dev",
              "search": ({"lr": [1.0], "width": sorted({c["width"] for c in grid})} if widths else
                         {n: list(v) for n, v in search.KNOBS.items()}),
              "kind": "width sweep" if widths else "search", "scored_by": scored_by(claim), "configs": grid,
              "seeds": splits.DEV.seeds(n_seeds), "frameworks": list(frameworks), "models": {}}
    for label, g in df.groupby("model", sort=False):
        by = g.groupby("config")["score"]   # a failed unit scores nothing; a config of failures, NaN
        mean = by.median() if claim.pooled else by.mean()
        best = int(mean.idxmin()) if mean.notna().any() else None
        ledger["models"][label] = {"configs_tried": int(g["config"].nunique()), "scored_on": "dev",
                                   "scores": {int(c): (None if pd.isna(v) else float(v)) for c, v in mean.items()},
                                   "chosen": best, "chosen_knobs": grid[best] if best is not None else None}
    R.write_json(Path(out) / "ledger.json", ledger)
    return ledger
