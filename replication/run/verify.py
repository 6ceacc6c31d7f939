"""`lagbench verify`: a results folder re-checked by retraining some of its units from scratch.

`verify(results, n, seed=0, jobs=1, progress=True, only=None) -> DataFrame`: picks `n` of the folder's finished
units at random (NumPy's generator seeded with `seed`, over the candidates sorted by name: the same seed picks the
same units), retrains each from nothing in a temporary folder through the code a run uses
(`executor.run_units`: no training cache, the unit's protocol, seed, framework and evaluation), each at the
threads it trained on (`trained_threads`: in `jobs` worker processes, one thread each, the units a run trained
in workers; in this process the others), and compares
what it gets with what the folder holds: every metric of result.json, the status, the final training loss,
the steps and samples trained. A metric of wall time (`TIMING`: microseconds per rollout step, a controller's
compute time) differs from run to run: it is written beside the others as "timing", not compared. The candidates are the units this code can rerun as they were made:
verified, of a claim and model this code has (a user's model is not: its code is not in the folder), and
current (`runner.is_current`: the same protocol, spec and evaluation as this code's). `only` ({"claims":
names, "frameworks": names, "models": names}, each optional) narrows the candidates before the draw, so that a
check can aim at a costly claim or at one framework; a name no candidate has is an error naming it.

Each value is "identical" (equal bit for bit; both absent or NaN count as equal), else its relative difference
|a - b| / max(|a|, |b|) is held against a tolerance: `SAME_TOL` where the unit retrained where it was made (the
same CPU model and vector features, GPU, training device, library versions and threads: training is deterministic
there, so any difference is a finding), `OTHER_TOL` elsewhere. float32 training is chaotic at the level of
rounding: another CPU's kernels or another library version round differently, the difference grows over
thousands of steps, and a rollout of a chaotic system (the double pendulum's valid-prediction time) can
amplify it past any fixed tolerance; so every difference is written out and shown, never only counted.

Writes RESULTS/verify/verify.csv (`COLUMNS`), adding this verification's rows to those of earlier ones (when
and where each ran: `lagbench report` says how many units were re-verified, where and when), and returns
this verification's rows. `summary(rows) -> str`: the lines `lagbench verify` prints.
"""
from __future__ import annotations

import json
import math
import re
import tempfile
from pathlib import Path

import numpy as np
import pandas as pd

from lagbench.files import results as R
from lagbench.models.spec import USER_KIND
from lagbench.replication.run import environment as env
from lagbench.replication.run.chains import unit_of
from lagbench.replication.run.executor import run_units
from lagbench.replication.run.runner import is_current
from lagbench.validate import is_integer

SAME_TOL = 1e-6    # relative, retrained where it was made: in practice every value is identical there
OTHER_TOL = 0.05   # relative, retrained on another CPU kind, device or library versions
VALUES = ("status", "final_train_loss", "train_steps", "train_samples")   # compared beside the metrics
SAME_HARDWARE = ("cpu_model", "cpu_features", "gpu")
COLUMNS = ["verified_at", "where", "unit", "value", "stored", "recomputed", "rel_diff", "tolerance", "outcome",
           "same_environment", "stored_commit", "commit", "note"]
FILE = Path("verify") / "verify.csv"
# a unit's outcome: the worst of its values; "timing": a wall-clock measurement, shown, never compared
OUTCOMES = ("timing", "identical", "within", "differs", "error")
TIMING = re.compile(r"(^|_)us(_|$)")   # metrics in microseconds of wall time (rollout_us_per_step, compute_us_p99)


def candidates(results) -> tuple[list, list[str]]:
    """(units this code can retrain as they were made, sorted by name; "<folder>: why" of the others)."""
    units, skipped = [], []
    for f in sorted(Path(results).glob("units/*/*/*/seed*/result.json")):
        rel = f.parent.relative_to(results).as_posix()
        try:
            d = R.load_result(f.parent)
        except R.CorruptResult:
            skipped.append(f"{rel}: unfinished or damaged")
            continue
        if (d.get("model_spec") or {}).get("kind") == USER_KIND:
            skipped.append(f"{rel}: a user's model (its code is not in the folder)")
            continue
        try:
            unit = unit_of((d["claim"], d["model"], d["framework"], d["seed"], d["profile"], None))
        except (KeyError, ValueError, TypeError):
            skipped.append(f"{rel}: a claim or model this code does not have")
            continue
        if not is_current(unit, results, set_stale_aside=False):
            skipped.append(f"{rel}: made under another protocol, spec or evaluation than this code's")
            continue
        units.append(unit)
    return sorted(units, key=lambda u: u.name), skipped


FILTERS = {"claims": ("--claims", lambda u: u.claim.id), "frameworks": ("--frameworks", lambda u: u.framework),
           "models": ("--models", lambda u: u.entry.label)}


def narrowed(units: list, only: dict | None) -> list:
    """The units whose claim, framework and model are among `only`'s names (a key left out or None: any)."""
    for key, names in (only or {}).items():
        if not names:
            continue
        option, name_of = FILTERS[key]
        have = {name_of(u) for u in units}
        missing = [n for n in names if n not in have]
        if missing:
            raise ValueError(f"{option} {','.join(names)}: no unit to retrain of {', '.join(missing)}"
                             f" (the folder's candidates have {', '.join(sorted(have)) or 'none'})")
        units = [u for u in units if name_of(u) in names]
    return units


def pick(units: list, n: int, seed: int) -> list:
    idx = np.random.default_rng(seed).choice(len(units), size=min(n, len(units)), replace=False)
    return [units[i] for i in sorted(idx)]


def same_environment(a: dict, b: dict) -> bool:
    """Whether two results were computed on the same kind of machine with the same libraries and threads, both
    packed with other seeds or both alone (a packed training's products run stacked: other rounding,
    `run.packing`), and for PyTorch with subnormal floats handled alike (`models.torch.subnormals`; not
    recorded: kept, as PyTorch does unless told)."""
    ha, hb = a.get("hardware") or {}, b.get("hardware") or {}
    ta, tb = trained_threads(a), trained_threads(b)
    return (all(ha.get(k) == hb.get(k) for k in SAME_HARDWARE) and a.get("versions") == b.get("versions")
            and a.get("train_device") == b.get("train_device") and _packed(a) == _packed(b)
            and ta is not None and ta == tb and _subnormals(a) == _subnormals(b))


def _subnormals(record: dict) -> str | None:
    if record.get("framework") != "torch":
        return None
    return (record.get("hardware") or {}).get("torch_subnormals") or "kept"


def trained_threads(record: dict) -> int | None:
    """The CPU threads a unit's framework trained on (they sum in their own order, so they are part of what its
    numbers are): as recorded (`environment.hardware`); where not recorded, JAX's pool at the machine's cores
    (what XLA sizes it to when the backend starts) and PyTorch's unknown (None)."""
    hw = record.get("hardware") or {}
    if record.get("framework") == "jax":
        return hw.get("jax_threads", hw.get("cores"))
    return hw.get("torch_threads")


def in_worker(record: dict) -> bool:
    """Whether a unit retrains in a worker process (one thread a framework) rather than in this process: it
    trained on one thread, or on threads not recorded (PyTorch's before they were: the suite's runs train in
    workers)."""
    threads = trained_threads(record)
    return threads is None or threads == env.WORKER_THREADS


def _packed(record: dict) -> bool:
    return bool((record.get("cohort") or {}).get("packed")) if isinstance(record.get("cohort"), dict) else False


def _number(v) -> bool:
    return isinstance(v, int | float) and not isinstance(v, bool)


def compare_value(a, b, tol: float) -> tuple[str, float | None]:
    """(outcome, relative difference) of a stored value `a` and a recomputed `b`."""
    if _number(a) and _number(b):
        a, b = float(a), float(b)
        if a == b or (math.isnan(a) and math.isnan(b)):
            return "identical", 0.0
        scale = max(abs(a), abs(b))
        rel = abs(a - b) / scale if math.isfinite(scale) and scale > 0 else math.inf
        return ("within" if rel <= tol else "differs"), rel
    return ("identical", None) if a == b else ("differs", None)


def _cell(v):
    return v if v is None or isinstance(v, str | int | float) else json.dumps(v, sort_keys=True)


def compare(stored: dict, new: dict) -> list[dict]:
    """One row per value (`VALUES` and every metric of either): stored, recomputed, outcome."""
    same = same_environment(stored, new)
    tol = SAME_TOL if same else OTHER_TOL
    a, b = {**(stored.get("metrics") or {})}, {**(new.get("metrics") or {})}
    a.update({k: stored.get(k) for k in VALUES})
    b.update({k: new.get(k) for k in VALUES})
    rows = []
    for name in [*VALUES, *sorted((set(a) | set(b)) - set(VALUES))]:
        outcome, rel = ("timing", None) if TIMING.search(name) else compare_value(a.get(name), b.get(name), tol)
        rows.append({"value": name, "stored": _cell(a.get(name)), "recomputed": _cell(b.get(name)), "rel_diff": rel,
                     "tolerance": tol, "outcome": outcome, "same_environment": same,
                     "stored_commit": stored.get("commit")})
    return rows


def where() -> str:
    hw = env.hardware()
    return f"{hw.get('cpu')} ({hw.get('cores')} cores), GPU {hw.get('gpu') or 'none'}, {hw.get('platform')}"


@R.writes
def verify(results, n: int, seed: int = 0, jobs: int = 1, progress: bool = True, only: dict | None = None) -> pd.DataFrame:
    results = Path(results)
    if not is_integer(n) or n < 1:
        raise ValueError(f"--units: {n!r} is not valid; expected an integer >= 1 (how many units to retrain)")
    if not is_integer(seed):
        raise ValueError(f"--seed: {seed!r} is not valid; expected an integer")
    if not (results / "units").is_dir():
        raise ValueError(f"--results {results}: no units/ folder; give a folder written by `lagbench run`")
    units, skipped = candidates(results)
    if not units:
        raise ValueError(f"--results {results}: no finished unit this code can retrain as it was made"
                         + (f" ({skipped[0]}{'; ...' if len(skipped) > 1 else ''})" if skipped else ""))
    units = narrowed(units, only)
    chosen = pick(units, n, seed)
    folder = R.output_folder(results / FILE.parent, "--results")
    at, here, commit = env.now(), where(), env.commit()
    rows = []
    with tempfile.TemporaryDirectory(prefix="lagbench-verify-") as tmp:
        stored = {u.name: R.load_result(u.folder(results)) for u in chosen}
        # each unit at the threads it trained on: in workers those a run trained in workers, here the others
        there = [u for u in chosen if in_worker(stored[u.name])]
        local = [u for u in chosen if u not in there]
        errors = ((run_units(local, tmp, "verify", progress, 1, workers=False)[1] if local else [])
                  + (run_units(there, tmp, "verify", progress, jobs, workers=True)[1] if there else []))
        failed = {e.partition(": ")[0]: e.partition(": ")[2] for e in errors}
        for u in chosen:
            try:
                new = R.load_result(u.folder(tmp))
            except R.CorruptResult:
                rows.append({"unit": u.name, "value": "-", "outcome": "error",
                             "stored_commit": stored[u.name].get("commit"),
                             "note": failed.get(u.name, "no result written")})
                continue
            rows += [{"unit": u.name, **r} for r in compare(stored[u.name], new)]
    df = pd.DataFrame(rows).assign(verified_at=at, where=here, commit=commit).reindex(columns=COLUMNS)
    path = folder / FILE.name
    if path.is_file():
        try:
            earlier = pd.read_csv(path)
        except (OSError, ValueError) as e:
            raise ValueError(f"{path}: unreadable ({e}); move it aside to verify again") from None
        R.write_csv(path, pd.concat([earlier, df], ignore_index=True))
    else:
        R.write_csv(path, df)
    df.attrs.update(candidates=len(units), skipped=skipped)
    return df


def unit_outcome(values: pd.Series) -> str:
    return max(values, key=OUTCOMES.index)


def summary(rows: pd.DataFrame) -> str:
    """What a verification found: its units and outcomes, and every value that is not identical."""
    units = rows["unit"].nunique()
    counts = rows.groupby("unit")["outcome"].agg(unit_outcome)
    tol = rows["tolerance"].dropna()
    lines = [f"lagbench verify: {units} of {rows.attrs.get('candidates', units)} units retrained from scratch on "
             f"{rows['where'].iloc[0]} at {rows['verified_at'].iloc[0]}: "
             + ", ".join(f"{int((counts == k).sum())} {k}" for k in OUTCOMES[1:])
             + (f" (relative tolerance {', '.join(f'{t:g}' for t in sorted(tol.unique()))})" if len(tol) else "")]
    skipped = rows.attrs.get("skipped") or []
    if skipped:   # finished units this code cannot retrain as they were made: never picked
        lines.append(f"  {len(skipped)} unit(s) not candidates, e.g. {skipped[0]}")
    for r in rows[~rows["outcome"].isin(("identical", "timing"))].itertuples(index=False):
        if r.outcome == "error":
            lines.append(f"  {r.unit}: error: {r.note}")
        else:
            rel = "" if pd.isna(r.rel_diff) else f", relative difference {r.rel_diff:.3g}"
            lines.append(f"  {r.unit} {r.value}: stored {r.stored}, recomputed {r.recomputed}{rel}: {r.outcome}")
    return "\n".join(lines)
