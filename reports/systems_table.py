"""Every model a results folder holds, per system: the suite's (one row per claim, model and framework, over
its seeds) and predictors scored by `lagbench evaluate --predict`.

``systems_table(root) -> DataFrame``: columns system, profile (the profile the numbers were made under: a
claim unit's, or the one a predictor was scored under), source ("claim" or "predictor"), claim, model,
framework, status ("ok"; a predictor's "failed: <why>", shown beside its numbers), seeds, params (`params_of`), train_samples and train_time_s (medians over seeds), and
for each of ``METRICS`` (errors, valid times against the chaos and float32 floors, rollout µs per step) its median, min and max over seeds (``<metric>``, ``<metric>_min``, ``<metric>_max``;
NaN where the claim's evaluation does not compute it). `lagbench table` writes it to
``summary/systems.csv`` and prints a table per system and profile; the report shows it (``systems_sections``).
Rows of different profiles are never in one table (``by_table``): a profile sets the training budget and
the held-out set, so a smoke row beside a quick one compares unlike things; ``mixed(df)`` names the systems
whose rows come from more than one profile, in words.
Counts (seeds, parameters, training samples) print as integers (``fmt.count``); an energy error beyond the
data's own scale reads "diverged" (``replication.evaluation.diverged``).
``excluded(root) -> [str]``: what the table leaves out (failed, corrupt and missing units; predictor records
that fail verification), in the words the report uses; `lagbench table` prints it.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from lagbench.replication.evaluation.diverged import SCALED, is_diverged
from lagbench.reports.confounds import parameters
from lagbench.reports.document import Para, Section, Table
from lagbench.reports.fmt import count, num
from lagbench.reports.load import load_results, protocol_of
from lagbench.reports.sections_predict import predictor_results, status_of
from lagbench.reports.tables import PROBLEM_UNITS, excluded_note, problem_units_table

METRICS = ("heldout_l1", "null_heldout_l1", "rollout_gmean_err", "energy_err_final", "vpt_s", "chaos_floor_vpt_s",
           "float32_truth_vpt_s", "lyapunov_time_s", "torque_mse_test", "rollout_us_per_step")


def params_of(unit) -> float:
    """The number of parameters of the unit's model (`confounds.parameters`: from its recorded spec, else its
    checkpoint, which a store keeps only where a later step loads it; NaN without either)."""
    n = parameters(unit)
    return np.nan if n is None else n


def _spread(values) -> dict:
    v = np.asarray([x for x in values if x is not None], float)
    if v.size == 0:
        return {"": np.nan, "_min": np.nan, "_max": np.nan}
    return {"": float(np.median(v)), "_min": float(np.min(v)), "_max": float(np.max(v))}


def systems_table(root, res=None) -> pd.DataFrame:
    """The table of the module doc; `res`, the folder's `load_results` where the caller has it already."""
    res, groups = res if res is not None else load_results(root), {}
    for u in res.usable():
        p = protocol_of(u.result)
        if p is None or p.data.recipe.startswith("file:"):
            continue
        key = (p.data.recipe.removesuffix("_iid"), str(u.result.get("profile") or "unknown"), u.claim, u.model,
               u.framework)
        groups.setdefault(key, []).append(u)
    rows = []
    for (system, profile, claim, model, fw), units in sorted(groups.items()):
        r = {"system": system, "profile": profile, "source": "claim", "claim": claim, "model": model, "framework": fw,
             "status": "ok", "seeds": len(units), "params": params_of(units[0]),
             "train_samples": _spread([u.result.get("train_time_s", 0) * (u.result.get("train_samples_per_s") or 0)
                                       for u in units])[""],
             "train_time_s": _spread([u.result.get("train_time_s") for u in units])[""]}
        for m in METRICS:
            r.update({m + k: v for k, v in _spread([u.metric(m) for u in units]).items()})
        rows.append(r)
    for d in predictor_results(Path(root))[0]:
        r = {"system": d["system"], "profile": str(d.get("profile") or "unknown"), "source": "predictor",
             "claim": d["scored_like"]["claim"], "model": d["model"],
             "framework": "-", "status": status_of(d), "seeds": 1, "params": np.nan, "train_samples": np.nan, "train_time_s": np.nan}
        for m in METRICS:
            v = d["metrics"].get(m)
            r.update({m + k: (np.nan if v is None else float(v)) for k in ("", "_min", "_max")})
        rows.append(r)
    return pd.DataFrame(rows)


def excluded(root, res=None) -> list[str]:
    """What the table leaves out, in the report's words: the note and the table of failed, corrupt and missing
    units of its "Run status", then each predictor record that fails verification ("...; not used")."""
    res = res if res is not None else load_results(root)
    bad = problem_units_table(res)
    lines = [] if bad is None else [excluded_note("table"), f"{PROBLEM_UNITS}:", bad.to_string(index=False)]
    return lines + predictor_results(Path(root))[1]


def shown(df: pd.DataFrame) -> pd.DataFrame:
    """One system's rows for reading: each metric as "median [min, max]" over seeds, empty columns left out."""
    out = df[["profile", "source", "claim", "model", "framework"]].copy()
    if (df["status"] != "ok").any():   # a failed predictor's numbers are not scores: it says why
        out.insert(5, "status", df["status"])
    out["seeds"] = [count(v, "–") for v in df["seeds"]]
    out["params"] = [count(v, "–") for v in df["params"]]
    out["train samples"] = [count(v, "–") for v in df["train_samples"]]
    out["train time (s)"] = [num(v) for v in df["train_time_s"]]
    for m in METRICS:
        if df[m].notna().any():
            def value(x, m=m):   # an energy error beyond the data's own scale: "diverged", never a number
                return "diverged" if m in SCALED and x == x and is_diverged(x) else num(x)
            out[m] = [value(a) if not (a == a) or n == 1 or lo == hi else f"{value(a)} [{value(lo)}, {value(hi)}]"
                      for a, lo, hi, n in zip(df[m], df[m + "_min"], df[m + "_max"], df["seeds"], strict=True)]
    return out


def by_table(df: pd.DataFrame) -> list[tuple[str, pd.DataFrame]]:
    """The rows as their tables: one per system and profile, titled by the system (and the profile where the
    system's rows come from more than one)."""
    out = []
    for system, g in df.groupby("system", sort=True):
        profiles = sorted(g["profile"].unique())
        for profile in profiles:
            title = system if len(profiles) == 1 else f"{system}, profile {profile}"
            out.append((title, g[g["profile"] == profile]))
    return out


def mixed(df: pd.DataFrame) -> list[str]:
    """For each system whose rows come from more than one profile, a line saying they are tabled apart."""
    return [f"{system}: rows of profiles {' and '.join(sorted(g['profile'].unique()))} are in separate tables: a "
            f"profile sets the training budget and the held-out set, so their numbers do not compare"
            for system, g in df.groupby("system", sort=True) if g["profile"].nunique() > 1]


def systems_sections(root) -> list[Section]:
    df = systems_table(root)
    if df.empty:
        return []
    s = Section("Results by system")
    s.add(Para("Every model this folder holds, per system and profile: median [min, max] over seeds; valid times "
               "in seconds against the chaos floor's (`docs/RESULTS.md`); `summary/systems.csv` (`lagbench table`) "
               "holds the numbers." + "".join(f" {line}." for line in mixed(df))))
    for title, g in by_table(df):
        s.add(Table(title, shown(g), ["units/*/*/*/seed*/result.json", "predict/*/*/result.json"]))
    return [s]
