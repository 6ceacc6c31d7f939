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
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from lagbench.replication.training.protocol import Protocol
from lagbench.reports.integrity import verify_unit

BENCH_COLUMNS = {
    "inference": ["system", "model", "formulation", "framework", "dtype", "batch", "samples_per_s", "error"],
    "training": ["system", "model", "framework", "mode", "dtype", "batch", "steps_per_s", "samples_per_s"],
    "rollout": ["system", "solver", "rtol", "kind", "wall_s", "state_err", "energy_err"],
    "scaling": ["study", "formulation", "framework", "n", "seconds_per_eval", "samples_per_s"],
    "ratios": ["operation", "jax", "torch", "ratio", "note"],
    "latency": ["system", "model", "method", "framework", "dtype", "mode", "dispatch", "evals_per_s"],
    "control_rate": ["model", "framework", "mode", "ticks", "mean_us", "median_us", "p99_us", "rate_hz_mean",
                     "rate_hz_p99", "fits_500hz_mean", "fits_500hz_p99"],
    "train_target": ["protocol", "description", "budget", "threshold", "samples_to_reach", "reached", "best_l1",
                     "samples_per_s", "extrapolated_samples", "extrapolation"],
    "train_target_log": ["protocol", "samples", "heldout_l1"],
    "members": ["framework", "members", "hidden", "batch", "steps", "wall_s", "step_s", "samples_per_s",
                "cost_vs_one"],
}
# `lagbench bench --gpu --out ROOT` writes ROOT/bench_gpu/: the GPU preset's stages
GPU_COLUMNS = {**{k: BENCH_COLUMNS[k] for k in ("inference", "training", "scaling", "ratios")},
               "fast_paper": ["dof", "framework", "formulation", "mode", "batch", "samples_per_s"]}
# `lagbench train-target --out ROOT` writes ROOT/train_target/ with the bench stage's two files
# and, with --runs N > 1, distribution.csv (one row per run at the target held-out L1)
TRAIN_TARGET_COLUMNS = {**{k: BENCH_COLUMNS[k] for k in ("train_target", "train_target_log")},
                        "distribution": ["protocol", "run", "init_seed", "split", "reached", "samples_to_reach",
                                         "wall_s_to_reach", "final_l1"]}
UNIT_KEYS = ("claim", "framework", "model", "seed", "status", "metrics")


def protocol_of(result: dict) -> Protocol | None:
    """A result's training protocol (any recorded version), or None where none is readable."""
    try:
        return Protocol.from_dict(result["protocol"])
    except (KeyError, TypeError, ValueError):
        return None


@dataclass(frozen=True)
class Unit:
    """One claim x framework x model x seed. ``rel`` is the unit folder relative to the results root."""

    claim: str
    framework: str
    model: str
    seed: str
    path: Path
    rel: str
    status: str
    reason: str | None = None
    result: dict = field(default_factory=dict, repr=False)

    @property
    def protocol(self) -> Protocol | None:
        return protocol_of(self.result)

    def metric(self, name: str) -> float | None:
        value = (self.result.get("metrics") or {}).get(name)
        return float(value) if isinstance(value, int | float) and not isinstance(value, bool) else None

    def table(self, name: str) -> pd.DataFrame | None:
        """A CSV of this unit (``train_log.csv``, ``rollouts.csv``, ``timeseries.csv``), or None."""
        path = self.path / name
        if self.status == "corrupt" or not path.is_file():
            return None
        try:
            return pd.read_csv(path)
        except (ValueError, OSError):
            return None

    def arrays(self) -> dict[str, np.ndarray] | None:
        """The arrays of ``arrays.npz`` (no pickles), or None."""
        path = self.path / "arrays.npz"
        if self.status == "corrupt" or not path.is_file():
            return None
        try:
            with np.load(path, allow_pickle=False) as npz:
                return {k: np.asarray(npz[k]) for k in npz.files}
        except (ValueError, OSError):
            return None


@dataclass
class Results:
    root: Path
    run: dict | None = None
    claims: list[dict] = field(default_factory=list)
    units: list[Unit] = field(default_factory=list)
    verdicts: dict[str, dict] = field(default_factory=dict)          # recomputed from the unit files
    stored_verdicts: dict[str, dict] = field(default_factory=dict)   # summary/verdicts.json as written
    verdict_profile: str | None = None
    verdict_split: str | None = None
    split: str = "dev"   # the split judged (`replication.run.splits`): run.json's, else verdicts.json's
    planned_missing: list[str] = field(default_factory=list)
    unfinished: bool = False
    units_csv: pd.DataFrame | None = None
    listed_missing: list[str] = field(default_factory=list)
    bench: dict[str, pd.DataFrame] = field(default_factory=dict)
    train_target: dict[str, pd.DataFrame] = field(default_factory=dict)  # train_target/ (lagbench train-target)
    bench_gpu: dict[str, pd.DataFrame] = field(default_factory=dict)  # bench_gpu/ (lagbench bench --gpu)
    machine: dict | None = None
    machine_gpu: dict | None = None
    problems: list[str] = field(default_factory=list)

    def usable(self, claim: str | None = None) -> list[Unit]:
        return [u for u in self.units if u.status == "ok" and (claim is None or u.claim == claim)]

    def claim_units(self, claim: str) -> list[Unit]:
        return [u for u in self.units if u.claim == claim]

    @property
    def frameworks(self) -> list[str]:
        declared = list((self.run or {}).get("frameworks") or [])
        seen = sorted({u.framework for u in self.units} - set(declared))
        return [str(f) for f in declared] + seen


def _read_json(path: Path, problems: list[str], root: Path) -> dict | None:
    if not path.is_file():
        return None
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (ValueError, OSError) as exc:
        problems.append(f"{path.relative_to(root)} unreadable: {exc}")
        return None
    if not isinstance(data, dict):
        problems.append(f"{path.relative_to(root)} is not a JSON object")
        return None
    return data


def _load_unit(root: Path, result_path: Path) -> Unit:
    unit_dir = result_path.parent
    rel = unit_dir.relative_to(root).as_posix()
    parts = unit_dir.relative_to(root / "units").parts
    claim, fw, model, seed = (list(parts) + ["?"] * 4)[:4]
    seed = seed.removeprefix("seed")
    try:
        result = json.loads(result_path.read_text(encoding="utf-8"))
        if not isinstance(result, dict):
            raise ValueError("not a JSON object")
    except (ValueError, OSError) as exc:
        return Unit(claim, fw, model, seed, unit_dir, rel, "corrupt", f"result.json unreadable: {exc}")
    reason = verify_unit(unit_dir, result)
    if reason is None:
        missing = [k for k in UNIT_KEYS if k not in result]
        if missing:
            reason = "missing keys: " + ", ".join(missing)
        elif (str(result["claim"]), str(result["framework"]), str(result["model"]), str(result["seed"])) \
                != (claim, fw, model, seed) or len(parts) != 4:
            reason = "folder does not match claim/framework/model/seed in result.json"
    if reason is not None:
        return Unit(claim, fw, model, seed, unit_dir, rel, "corrupt", reason, result)
    status = "ok" if result.get("status") == "ok" else "failed"
    failure = result.get("failure") or {}
    why = None if status == "ok" else str(failure.get("kind") or failure.get("message") or result.get("status"))
    return Unit(claim, fw, model, seed, unit_dir, rel, status, why, result)


def _seed_key(seed: str) -> tuple[int, str]:
    return (int(seed), "") if seed.isdigit() else (1 << 30, seed)


def asked_claims(root: Path, run: dict | None = None, earlier: bool = True) -> set[str] | None:
    """The claims `lagbench run` was asked for in `root`: the "claims" of its run.json (`run`, read from `root`
    when not given) and, with `earlier`, of every earlier invocation's record (runs/run-*.json); None where
    run.json records none (an older run, or a folder of another command): then every claim is the folder's."""
    root = Path(root)
    run = run if run is not None else _read_json(root / "run.json", [], root)
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


def _load_csvs(res: Results, folder: str, wanted: dict, into: dict) -> None:
    """ROOT/folder/<name>.csv for each name of `wanted` that exists and has its columns, into `into`."""
    for name, columns in wanted.items():
        path = res.root / folder / f"{name}.csv"
        if not path.is_file():
            continue
        try:
            df = pd.read_csv(path)
        except (ValueError, OSError) as exc:
            res.problems.append(f"{folder}/{name}.csv unreadable: {exc}")
            continue
        missing = [c for c in columns if c not in df.columns]
        if missing:
            res.problems.append(f"{folder}/{name}.csv lacks columns {missing}; not used")
            continue
        into[name] = df


def _load_bench(res: Results) -> None:
    res.machine = _read_json(res.root / "bench" / "machine.json", res.problems, res.root)
    _load_csvs(res, "bench", BENCH_COLUMNS, res.bench)
    _load_csvs(res, "train_target", TRAIN_TARGET_COLUMNS, res.train_target)
    if (res.root / "bench_gpu").is_dir():
        res.machine_gpu = _read_json(res.root / "bench_gpu" / "machine.json", res.problems, res.root)
        _load_csvs(res, "bench_gpu", GPU_COLUMNS, res.bench_gpu)


def load_results(root: str | Path) -> Results:
    """Read everything under ``root``; a missing or empty folder gives an empty :class:`Results`."""
    root = Path(root)
    res = Results(root=root)
    if not root.is_dir():
        res.problems.append(f"results folder {root} does not exist")
        return res
    res.run = _read_json(root / "run.json", res.problems, root)
    claims_json = _read_json(root / "claims.json", res.problems, root)
    verdicts = _read_json(root / "summary" / "verdicts.json", res.problems, root) or {}
    res.verdict_profile = verdicts.get("profile")
    res.verdict_split = verdicts.get("split")
    res.split = (res.run or {}).get("split") or res.verdict_split or "dev"
    for v in verdicts.get("claims") or []:
        if isinstance(v, dict) and isinstance(v.get("id"), str):
            res.stored_verdicts[v["id"]] = v
    units_dir = root / "units"
    if units_dir.is_dir():
        # results superseded by a later protocol (folders "superseded-<time>-seed<k>") are history, not units
        found = [_load_unit(root, p) for p in sorted(units_dir.rglob("result.json"))
                 if not p.parent.name.startswith("superseded-")]
        mine = [u for u in found if not u.result or (u.result.get("split") or "dev") == res.split]
        if len(mine) < len(found):   # one split a report: the other's seeds are neither shown nor judged
            res.problems.append(f"{len(found) - len(mine)} unit(s) of another split than this run's ({res.split}) "
                                f"are in this folder and left out of this report")
        found = mine
        res.units = sorted(found, key=lambda u: (u.claim, u.framework, u.model, _seed_key(u.seed)))
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
    _load_bench(res)
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
