"""`lagbench tune --claim ID`: every model of a claim searched alike on the development split.

The declared search (`kind` "search"), the same for every model of the claim:
1. grid: every configuration of `search.grid()` (peak rate x 1/3, 1, 3 by widths x 1/2, 1, 2; budget,
   restarts and input scaling as registered), trained on development seed 0 (a pooled claim: a cohort of
   `POOLED_SEEDS` development seeds) and scored by `choose.score_metric`.
2. edge: where a model's best configuration (an ablation's joint choice: `choose.joint`) lies on an edge of
   a knob's range, the configuration one step further (`search.extensions`); the union of those points is
   tried for every model alike, once; a point beyond the claim's declared `search.EDGE_LIMITS` is not tried,
   and the ledger names it (`edge_limits`, `edge_stopped`).
3. confirmation (`CONFIRM_SEEDS` development seeds; a pooled claim's cohort is its confirmation): each
   model's best configuration and the registered one (the runner-up where the best is the registered) are
   trained on development seeds 1 and 2 too; the one with the lower mean over the three seeds is chosen.
`tune(..., n_configs=N)` tries the first N configurations of `search.configs` alone (`kind` "partial
search") and `widths=[...]` a width sweep (`kind` "width sweep"): lab tools that no claim may adopt.

Units go to OUT/config<k>/units/... (a rerun into the same OUT reads back what is finished). With `record`,
each finished unit is also appended to that CSV as one small row (`records`): a search that resumes from a
committed record trains only what is missing, on any machine. With `jobs` > 1 the models of a configuration
train side by side in worker processes (`run.executor`), each unit recorded as it ends. Before each stage `lagbench tune` prints the
trainings left and their estimated time (`replication.run.estimate`); `dry_run` prints the first stage's
and stops. The ledger goes to OUT/ledger.json and OUT/ledger.csv: per model the configurations tried, their
scores, the confirmation, the chosen one, and the compute the search took; with `record`, beside the record
too (the folder to commit and adopt from).
What it does not do: change a claim. A ledger's choices reach the claim only when adopted
(`python -m lagbench.replication.tuning.adopt OUT/ledger.json`) and registered (a new dated line).
"""
from __future__ import annotations

import dataclasses
from pathlib import Path

import pandas as pd

from lagbench.files import results as R
from lagbench.replication.claims import get, tuned
from lagbench.replication.run import splits
from lagbench.replication.run.estimate import estimate
from lagbench.replication.run.executor import check_jobs, run_units
from lagbench.replication.run.runner import is_current
from lagbench.replication.run.units import Unit
from lagbench.replication.tuning import choose, records, search
from lagbench.validate import is_integer

CONFIRM_SEEDS = 3   # development seeds the chosen configuration is confirmed on, against the registered one
POOLED_SEEDS = 8    # a pooled claim's cohort of development seeds per configuration (its confirmation too)
STAGES = ("grid", "edge", "confirmation")


class _Runner:
    """Trains the units of a stage (or reads them back from OUT or the record) and keeps every row."""

    def __init__(self, claim, profile, labels, frameworks, out, record, progress, jobs=1):
        self.claim, self.profile, self.labels, self.frameworks = claim, profile, labels, frameworks
        self.out, self.record, self.progress, self.jobs = out, record, progress, jobs
        scored_by = {choose.PACE} if claim.pooled else {claim.metric, "heldout_l1"}
        # a row scored by another metric (the claim's metric changed) is not this search's: redone
        self.known = {k: r for k, r in (records.read(record) if record else {}).items() if r["metric"] in scored_by}
        self.base = claim.protocol(profile)
        self.rows: list[dict] = []

    def units(self, knobs: dict, labels, seeds) -> list[Unit]:
        models = tuple(search.apply(e, self.base, self.profile, knobs) if e.label in self.labels else e
                       for e in self.claim.models)
        variant = dataclasses.replace(self.claim, models=models)
        return [Unit(variant, e, fw, seed, self.profile) for e in models if e.label in labels
                for fw in self.frameworks for seed in seeds]

    def todo(self, plan) -> list[Unit]:
        return [u for k, knobs, labels, seeds in plan for u in self.units(knobs, labels, seeds)
                if records.unit_key(u) not in self.known and not is_current(u, self.folder(k), set_stale_aside=False)]

    def folder(self, k: int) -> Path:
        return self.out / f"config{k}"

    def tell(self, stage: str, plan) -> None:
        if not self.progress:
            return
        todo = self.todo(plan)
        if not todo:
            print(f"{self.claim.id} {stage}: every unit finished", flush=True)
            return
        est = estimate(todo, self.out)
        print(f"{self.claim.id} {stage}: {len(todo)} units to train and evaluate, about "
              f"{est['train_s'] / 3600:.2f} h of training on this machine", flush=True)

    def run(self, stage: str, plan) -> None:
        """`plan`: [(config index, knobs, labels, seeds)]; each model's units of a configuration as one run."""
        self.tell(stage, plan)
        for k, knobs, labels, seeds in plan:
            # one model at a time, or with jobs > 1 a configuration's models side by side; each unit's row
            # joins the record as soon as its run ends, so that the record grows as units finish
            for group in ([[label] for label in labels] if self.jobs == 1 else [list(labels)]):
                keyed = [(records.unit_key(u), u) for u in self.units(knobs, group, seeds)]
                todo = [(key, u) for key, u in keyed if key not in self.known]
                train = [u for _, u in todo if not is_current(u, self.folder(k))]
                if train:
                    run_units(train, self.folder(k), self.profile, self.progress, jobs=self.jobs,
                              on_done=lambda u, k=k, knobs=knobs: self._keep(self._row(records.unit_key(u), u, k, knobs)))
                self._keep(*[self._row(key, u, k, knobs) for key, u in todo if key not in self.known])
                self.rows += [{**self.known[key], "stage": stage, "config": k} for key, _ in keyed]

    def _keep(self, *rows) -> None:
        if rows and self.record:
            records.append(self.record, list(rows))
        self.known.update({r["key"]: r for r in rows})

    def _row(self, key: str, u: Unit, k: int, knobs: dict) -> dict:
        try:
            r = R.load_result(u.folder(self.folder(k)))
        except R.CorruptResult:
            r = {}
        ok = r.get("status") == "ok"
        return {"key": key, "claim": self.claim.id, "profile": self.profile, "model": u.entry.label,
                "config": k, "knob_lr": knobs["lr"], "knob_width": knobs["width"], "framework": u.framework,
                "seed": u.seed, "split": u.split, "status": r.get("status", "failed"),
                "metric": choose.score_name(r, self.claim),
                "score": choose.score_metric(r, self.claim) if ok else None,
                "train_time_s": r.get("train_time_s"), "train_samples": r.get("train_samples"),
                "cpu": (r.get("hardware") or {}).get("cpu_model")}


def _plan(configs, labels, seeds, ks=None):
    return [(k, configs[k], labels, seeds) for k in (range(len(configs)) if ks is None else ks)]


def _choices(claim, df, ks) -> tuple[dict, dict | None]:
    """{model: chosen config} over configurations `ks`, and an ablation's joint ranks."""
    scores = choose.config_scores(df[df["config"].isin(ks)], claim)
    if claim.pooled:
        ranks, k = choose.joint(scores)
        return {label: k for label in scores}, ranks
    return {label: choose.best(s) for label, s in scores.items()}, None


def _compute(df: pd.DataFrame, pooled: bool) -> dict:
    """Training seconds the search took (a cohort trains its seeds as one, each row holding the total)."""
    g = df.drop_duplicates("key").groupby(["model", "config"])["train_time_s"]
    per = g.max() if pooled else g.sum()
    by_model = per.groupby(level=0).sum()
    return {"train_s": float(per.sum()), "units": int(df["key"].nunique()),
            "by_model": {str(k): float(v) for k, v in by_model.items()},
            "cpu": sorted({str(c) for c in df["cpu"].dropna()})}


@R.writes
def tune(claim_id: str, profile: str = "quick", frameworks=("jax",), out="results/tune", progress: bool = True,
         n_configs: int | None = None, n_seeds: int | None = None, widths=None, record=None,
         confirm: int = CONFIRM_SEEDS, dry_run: bool = False, seeds=None, jobs: int = 1) -> dict | None:
    """`n_seeds`: the first development seeds each configuration trains on; `seeds`: those seeds themselves;
    `jobs`: worker processes, each a unit of one configuration at a time (`run.executor`; a worker's one CPU
    thread rounds float32 otherwise than a multithreaded process, so its scores differ from `jobs` = 1's at the
    level of rounding)."""
    claim = get(claim_id)   # the search is around the claim as written, never around an adopted choice
    if seeds is not None:
        seeds = list(dict.fromkeys(seeds))
        outside = [s for s in seeds if not (is_integer(s) and splits.DEV.holds(s))]
        if not seeds or outside:
            raise ValueError(f"--seeds: {', '.join(map(str, outside)) or 'none given'}: not development seeds; "
                             f"expected integers from 0 to {splits.SEEDS_PER_SPLIT - 1}")
        n_seeds = len(seeds)
    pooled_seeds = POOLED_SEEDS if claim.pooled else 1
    n_seeds = pooled_seeds if n_seeds is None else n_seeds
    if not is_integer(n_seeds) or not 1 <= n_seeds <= splits.SEEDS_PER_SPLIT:
        raise ValueError(f"--n-seeds: {n_seeds!r} is not valid; expected an integer from 1 to {splits.SEEDS_PER_SPLIT}")
    if not is_integer(confirm) or not 1 <= confirm <= splits.SEEDS_PER_SPLIT:
        raise ValueError(f"--confirm: {confirm!r} is not valid; expected an integer from 1 to {splits.SEEDS_PER_SPLIT}")
    check_jobs(jobs)
    kind = "width sweep" if widths else "partial search" if n_configs else "search"
    configs = search.sweep(widths) if widths else search.configs(n_configs) if n_configs else search.grid()
    labels = [e.label for e in claim.models if tuned.searched(claim, e, profile)]
    if not labels:
        raise ValueError(f"--claim {claim_id}: trains no model under profile {profile!r}")
    out = R.output_folder(out, "--out")
    if record is not None:
        record = Path(record)
        R.output_folder(record.parent, "--record")
    runner = _Runner(claim, profile, labels, tuple(frameworks), out, record, progress, jobs)
    seeds = splits.DEV.seeds(n_seeds) if seeds is None else seeds
    if dry_run:
        runner.tell("grid", _plan(configs, labels, seeds))
        return None
    runner.run("grid", _plan(configs, labels, seeds))
    df = pd.DataFrame(runner.rows)
    first, ranks = _choices(claim, df, range(len(configs)))
    confirmation, limits, kept_out = {}, {}, []
    if kind == "search":
        best = [configs[k] for k in first.values() if k is not None]
        limits = search.EDGE_LIMITS.get((claim.id, profile), {})
        ext, kept_out = search.extensions(configs, best, limits), search.stopped(configs, best, limits)
        configs = configs + ext
        runner.run("edge", _plan(configs, labels, seeds, range(len(configs) - len(ext), len(configs))))
        df = pd.DataFrame(runner.rows)
        first, ranks = _choices(claim, df, range(len(configs)))
        if not claim.pooled and confirm > n_seeds:
            confirmation = _confirm(runner, claim, configs, first, seeds, splits.DEV.seeds(confirm))
    df = pd.DataFrame(runner.rows)
    ledger = _ledger(claim, profile, kind, configs, seeds, frameworks, df, first, ranks, confirmation, labels)
    if kind == "search" and limits:
        ledger["edge_limits"], ledger["edge_stopped"] = dict(limits), kept_out
    for folder in dict.fromkeys([out, *([record.parent] if record is not None else [])]):
        R.write_csv(folder / "ledger.csv", df.drop(columns=["key"]))
        R.write_json(folder / "ledger.json", ledger)
    return ledger


def _confirm(runner, claim, configs, first, seeds, confirm_seeds) -> dict:
    """Each model's best and the registered configuration (else the runner-up) on every confirmation seed;
    {model: {"seeds", "configs": {config: mean}, "chosen"}}."""
    scores = choose.config_scores(pd.DataFrame(runner.rows), claim)
    pairs = {}
    for label, k in first.items():
        if k is None:
            continue
        rest = {c: v for c, v in scores[label].items() if c != k}
        other = 0 if k != 0 else choose.best(rest)
        pairs[label] = [k] if other is None else [k, other]
    extra = [s for s in confirm_seeds if s not in seeds]
    plan = [(k, configs[k], [label], extra) for label, ks in pairs.items() for k in ks]
    runner.run("confirmation", plan)
    df = pd.DataFrame(runner.rows)
    out = {}
    for label, ks in pairs.items():
        g = df[(df["model"] == label) & df["seed"].isin(confirm_seeds)]
        means = choose.config_scores(g[g["config"].isin(ks)], claim).get(label, {})
        means = {k: means.get(k) for k in ks}
        out[label] = {"seeds": list(confirm_seeds), "configs": means, "chosen": choose.best(means)}
    return out


def _ledger(claim, profile, kind, configs, seeds, frameworks, df, first, ranks, confirmation, labels) -> dict:
    scores = choose.config_scores(df[df["seed"].isin(seeds)], claim)
    values = {n: sorted({c[n] for c in configs}) for n in search.KNOBS}
    ledger = {"schema": R.SCHEMA, "claim": claim.id, "profile": profile, "split": "dev", "kind": kind,
              "search": values, "scored_by": choose.scored_by(claim), "configs": configs, "seeds": seeds,
              "frameworks": list(frameworks), "stages": [s for s in STAGES if s in set(df["stage"])],
              "compute": _compute(df, claim.pooled),
              "differs_by_model": choose.hand_chosen(claim, profile, labels), "models": {}}
    if ranks is not None:
        ledger["joint"] = {"rule": "one configuration for every arm: the lowest mean over arms of each arm's "
                           "rank of the configurations", "mean_rank": {int(k): v for k, v in ranks.items()}}
    for label in labels:
        conf = confirmation.get(label)
        chosen = conf["chosen"] if conf and conf["chosen"] is not None else first.get(label)
        ledger["models"][label] = {
            "configs_tried": len(scores.get(label, {})), "scored_on": "dev",
            "scores": {int(k): v for k, v in scores.get(label, {}).items()}, "first_choice": first.get(label),
            "confirm_seeds": conf["seeds"] if conf else (seeds if claim.pooled else []),
            "confirmation": {int(k): v for k, v in conf["configs"].items()} if conf else None,
            "chosen": chosen, "chosen_knobs": configs[chosen] if chosen is not None else None}
    return ledger
