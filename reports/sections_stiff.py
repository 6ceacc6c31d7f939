"""The stiff-solver section: ``OUT/stiff/solvers.csv`` and ``choice.json`` from ``lagbench stiff``.

``stiff_sections(res) -> list[Section]``: which ground-truth solver stays accurate on a stiff system, at
what cost (wall time after compilation, accepted steps), and the solver the suite picks with its reason.
"""

from __future__ import annotations

import json

import pandas as pd

from lagbench.reports.document import Para, Section, Table
from lagbench.reports.fmt import num
from lagbench.reports.load import Results

COLS = ["solver", "rtol", "dt", "wall_s", "n_steps", "state_err", "energy_err", "picked"]


def _cell(col: str, v) -> str:
    if col == "picked":
        return "picked" if bool(v) else "–"
    if isinstance(v, str):
        return v
    return "–" if pd.isna(v) else num(v)


def stiff_sections(res: Results) -> list[Section]:
    folder = res.root / "stiff"
    s = Section("Stiff systems: solver selection")
    try:
        df = pd.read_csv(folder / "solvers.csv")
        choice = json.loads((folder / "choice.json").read_text())
    except (OSError, ValueError):
        return [s.add(Para("Not run (`lagbench stiff --out RESULTS` writes stiff/solvers.csv)."))]
    missing = [c for c in COLS if c not in df.columns]
    if missing:
        return [s.add(Para(f"stiff/solvers.csv lacks columns {missing}; not used."))]
    s.add(Para(f"System {choice.get('system', '?')}: stiffness ratio (fastest / slowest linearised rate) "
               f"{num(choice.get('stiffness_ratio'))}. The suite's choice (`systems.stiffness.pick_solver`): "
               f"{choice.get('reason', 'no reason recorded')}. Errors are against dopri8 at rtol = atol = 1e-13; "
               "state_err is the largest final-state error, energy_err the largest relative energy drift."))
    table = pd.DataFrame([{c: _cell(c, r[c]) for c in COLS} for _, r in df.iterrows()])
    return [s.add(Table("Solvers on the stiff system: cost against accuracy", table,
                        ["stiff/solvers.csv", "stiff/choice.json"]))]
