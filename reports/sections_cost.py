"""Where a run's time went, measured: ``cost_sections(res) -> list[Section]``.

The sittings (``run.json`` and the earlier invocations' records in ``runs/``, one row each: when it started,
how it ended, its wall hours, the units it ran, its workers) and their total; then the units' own time, by
claim and by claim, model and framework. Worker hours are the units' ``wall_time_s`` (training where the unit
trained, and its evaluation) summed, so with two workers about twice the wall hours; a unit resumed from a
training snapshot records its last sitting's wall time only. Training hours count each training once, where
several units read it (a second claim on the same model, a cohort's other seeds): of the units of one training
(framework, model spec, protocol, seed or cohort) the one of the longest wall time, the one that trained,
carries its ``train_time_s``, which sums the training's sittings. Nothing where no unit records its time.
"""

from __future__ import annotations

import json

import pandas as pd

from lagbench.reports.document import Para, Section, Table
from lagbench.reports.fmt import num
from lagbench.reports.load import Results

SOURCES = ["units/*/*/*/seed*/result.json", "run.json", "runs/run-*.json"]


def _seconds(d: dict, key: str) -> float:
    v = d.get(key)
    return float(v) if isinstance(v, int | float) and not isinstance(v, bool) and v >= 0 else 0.0


def training_key(framework: str, seed, result: dict) -> str:
    """What identifies a unit's training: its framework, model spec, protocol and seed (a cohort's seeds)."""
    cohort = (result.get("cohort") or {}).get("seeds") if isinstance(result.get("cohort"), dict) else None
    return json.dumps([framework, result.get("model_spec"), result.get("protocol"), cohort or str(seed)],
                      sort_keys=True, default=str)


def unit_costs(res: Results) -> pd.DataFrame:
    """One row per unit: claim, model, framework, worker seconds (its wall time) and training seconds (its
    training's, on the one unit that carries it)."""
    carrier: dict = {}   # training -> (wall seconds, index) of the unit that carries it: the longest, which trained
    for i, u in enumerate(res.units):
        key, wall = training_key(u.framework, u.seed, u.result), _seconds(u.result, "wall_time_s")
        carrier[key] = max(carrier.get(key, (-1.0, -1)), (wall, -i))
    carriers = {-i for _, i in carrier.values()}
    rows = [{"claim": u.claim, "model": u.model, "framework": u.framework,
             "worker_s": _seconds(u.result, "wall_time_s"),
             "train_s": _seconds(u.result, "train_time_s") if i in carriers else 0.0}
            for i, u in enumerate(res.units)]
    return pd.DataFrame(rows, columns=["claim", "model", "framework", "worker_s", "train_s"])


def sittings(res: Results) -> pd.DataFrame:
    """One row per invocation of the run that recorded its wall time: the earlier ones kept in runs/, then
    run.json's."""
    records = []
    for path in sorted((res.root / "runs").glob("run-*.json")):
        try:
            records.append(json.loads(path.read_text()))
        except (OSError, ValueError):
            continue
    records.append(res.run or {})
    rows = []
    for d in records:
        if not isinstance(d, dict) or not _seconds(d, "wall_time_s"):
            continue
        ended = ("finished" if d.get("finished") else "interrupted" if d.get("interrupted") else
                 "stopped" if d.get("stopped") else "unknown")
        rows.append({"started": d.get("started"), "ended": ended, "wall h": _seconds(d, "wall_time_s") / 3600,
                     "units run": d.get("units_run", "–"), "workers": d.get("jobs", "–"),
                     "machine": (d.get("hardware") or {}).get("cpu", "–") if isinstance(d.get("hardware"), dict)
                     else "–"})
    return pd.DataFrame(rows)


def _hours(df: pd.DataFrame, by: list[str]) -> pd.DataFrame:
    g = df.groupby(by, sort=False).agg(units=("worker_s", "size"), worker_s=("worker_s", "sum"),
                                       train_s=("train_s", "sum")).reset_index()
    g = g.sort_values("worker_s", ascending=False, kind="stable")
    total = g["worker_s"].sum()
    g["share"] = [f"{100 * v / total:.0f} %" if total else "–" for v in g["worker_s"]]
    g["worker h"] = g.pop("worker_s") / 3600
    g["training h"] = g.pop("train_s") / 3600
    return g[[*by, "units", "worker h", "training h", "share"]].reset_index(drop=True)


def _shown(df: pd.DataFrame) -> pd.DataFrame:
    """Hours to three significant digits."""
    return df.assign(**{c: [num(v) for v in df[c]] for c in ("wall h", "worker h", "training h") if c in df})


def cost_sections(res: Results) -> list[Section]:
    costs = unit_costs(res)
    if not len(costs) or not costs["worker_s"].sum():
        return []
    s = Section("Where the time went")
    runs = sittings(res)
    if len(runs):
        s.add(Para(f"The run took {runs['wall h'].sum():.2f} h of wall time over {len(runs)} sitting"
                   f"{'s' if len(runs) != 1 else ''}; its units {costs['worker_s'].sum() / 3600:.2f} worker hours, "
                   f"{costs['train_s'].sum() / 3600:.2f} of them training (a training shared by several units "
                   "counted once, where it ran). Worker hours add up over the run's workers."))
        s.add(Table("The run's sittings", _shown(runs), SOURCES[1:]))
    s.add(Table("Time by claim (measured; the costliest first)", _shown(_hours(costs, ["claim"])), SOURCES[:1]))
    s.add(Table("Time by claim, model and framework", _shown(_hours(costs, ["claim", "model", "framework"])),
                SOURCES[:1]))
    return [s]
