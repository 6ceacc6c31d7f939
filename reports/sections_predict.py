"""The section of predictors from outside the suite: ``OUT/predict/<system>/<label>/result.json`` from
``lagbench evaluate --predict``.

``predictor_results(root) -> (rows, problems)``: each verified record (its checksum and files), one row per
predictor; a record that fails verification is named among the problems and not used.
``predict_sections(root) -> list[Section]``: a table per system, every predictor beside the null predictor
and the chaos floor, with the claim and model whose evaluation scored it and its status ("ok", or "failed:
non-finite on k of n held-out states": `status_of`); empty when none was scored.
"""
from __future__ import annotations

import json
from pathlib import Path

import pandas as pd

from lagbench.reports.document import Para, Section, Table
from lagbench.reports.fmt import num
from lagbench.reports.integrity import verify_unit

COLUMNS = {"heldout_l1": "held-out L1", "null_heldout_l1": "null's held-out L1", "rollout_gmean_err": "rollout error",
           "energy_err_final": "final energy error", "vpt_s": "valid time (s)",
           "chaos_floor_vpt_s": "chaos floor's valid time (s)", "lyapunov_time_s": "Lyapunov time (s)",
           "vpt_lyapunov": "valid time (Lyapunov times)", "predict_s_per_state": "s per state"}


def status_of(d: dict) -> str:
    """"ok", or "failed: <why>" (a predictor with a non-finite prediction on a held-out state)."""
    failure = d.get("failure") or {}
    return "ok" if d.get("status", "ok") == "ok" else f"failed: {failure.get('message', 'no reason recorded')}"


def predictor_results(root: Path) -> tuple[list[dict], list[str]]:
    rows, problems = [], []
    for path in sorted(Path(root).glob("predict/*/*/result.json")):
        rel = path.parent.relative_to(root)
        try:
            d = json.loads(path.read_text())
        except (OSError, ValueError) as e:
            problems.append(f"{rel}: unreadable ({e})")
            continue
        why = verify_unit(path.parent, d)
        if why:
            problems.append(f"{rel}: {why}; not used")
            continue
        rows.append(d)
    return rows, problems


def predict_sections(root: Path) -> list[Section]:
    rows, problems = predictor_results(root)
    if not rows and not problems:
        return []
    s = Section("Your predictors")
    s.add(Para("Functions scored by `lagbench evaluate --predict`, each as the suite scores its own model of the "
               "system (that claim's held-out set, rollouts and evaluation, test split). The null predictor is the "
               "better of zero and the mean target; the chaos floor is the truth against the truth from starts "
               "moved by 1e-8 (`docs/RESULTS.md`)."))
    for system in sorted({d["system"] for d in rows}):
        mine = [d for d in rows if d["system"] == system]
        df = pd.DataFrame([{"predictor": d["model"], "function": d.get("predictor", ""),
                            "scored as": f"{d['scored_like']['claim']} / {d['scored_like']['model']}",
                            "profile": d.get("profile", ""), "status": status_of(d),
                            **{label: num(d["metrics"].get(k)) for k, label in COLUMNS.items()}} for d in mine])
        s.add(Table(f"{system}: predictors from outside the suite", df,
                    [f"predict/{system}/{d['model']}/result.json" for d in mine]))
    for p in problems:
        s.add(Para(p))
    return [s]
