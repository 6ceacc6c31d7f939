"""The velocity-Hessian health section: how often LNN / LGN Hessians are indefinite or singular during
training and at evaluation, how often the `fast` solve fell back to pinv, and the largest acceleration.

``hessian_sections(res) -> list[Section]`` reads each unit's ``train_log.csv`` probe columns (written by
``replication.training.hessian_probe``) and ``result.json`` counters; failed units are included (a blow-up is
where the Hessian matters most), corrupt ones are not.
"""

from __future__ import annotations

import pandas as pd

from lagbench.reports.document import Para, Section, Table
from lagbench.reports.fmt import num
from lagbench.reports.load import Results

INTRO = ("The Euler-Lagrange step solves (d2L/dqdot2) qddot = rhs. Indefinite: the Hessian has eigenvalues "
         "of both signs (solvable, but the learned kinetic energy is not convex). Singular: its smallest "
         "|eigenvalue| is at or below pinv's relative cutoff, where the paper's pinv drops a direction and "
         "the fast solve would return a huge acceleration; the fast formulation then takes the counted pinv "
         "fallback. Fractions are of the training batch at each logged step (first, mean, last) and of the "
         "held-out set at evaluation.")


def _row(u) -> dict | None:
    log = u.table("train_log.csv")
    counters = u.result.get("counters") or {}
    if log is None or "hessian_fallbacks" not in log.columns:
        return None
    ind = log.get("hessian_indefinite_fraction")
    spec = u.result.get("model_spec") or {}

    def series(s, how):
        s = None if s is None else s.dropna()
        if s is None or not len(s):
            return "–"
        return num({"first": s.iloc[0], "mean": s.mean(), "last": s.iloc[-1], "max": s.max()}[how])
    return {"claim": u.claim, "framework": u.framework, "model": u.model, "seed": u.seed,
            "formulation": str(spec.get("formulation", "–")), "status": u.status,
            "indefinite first / mean / last": " / ".join(series(ind, h) for h in ("first", "mean", "last")),
            "singular max": series(log.get("hessian_singular_fraction"), "max"),
            "fallbacks (train, total)": str(int(log["hessian_fallbacks"].fillna(0).sum())),
            "max |qddot| (train)": series(log.get("qddot_max_abs"), "max"),
            "indefinite (eval)": num(counters["hessian_indefinite_fraction"])
            if "hessian_indefinite_fraction" in counters else "–",
            "fallbacks (eval)": str(counters.get("hessian_fallbacks", "–"))}


def hessian_sections(res: Results) -> list[Section]:
    s = Section("Velocity-Hessian health (LNN and LGN)").add(Para(INTRO))
    rows = [r for u in res.units if u.status != "corrupt" for r in [_row(u)] if r is not None]
    if not rows:
        return [s.add(Para("No unit logged the Hessian probe (runs made before it existed, or no LNN/LGN)."))]
    df = pd.DataFrame(rows).sort_values(["claim", "model", "framework", "seed"], kind="stable")
    s.add(Table("Velocity-Hessian health per unit", df.reset_index(drop=True),
                ["units/*/*/*/seed*/train_log.csv", "units/*/*/*/seed*/result.json"]))
    return [s]
