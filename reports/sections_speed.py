"""Speed-against-error sections.

Speed: per claim, every usable unit as a point (training throughput or time against the claim metric),
the cheapest-model table, and from the speed study (``bench/*.csv``, when present) the inference
speed-error plane, the cheapest model per system, training/rollout/scaling tables and figures.
The cross-framework section is ``reports.sections_frameworks``.
"""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from lagbench.reports import figures_speed as FS
from lagbench.reports.compare import (
    TOLERANCE,
    bench_cheapest_table,
    cheapest_table,
    gpu_vs_cpu_table,
)
from lagbench.reports.document import NOT_RUN, Figure, Para, Section, Table
from lagbench.reports.fmt import cell
from lagbench.reports.load import Results
from lagbench.reports.sections_claims import slug

BENCH_TABLE_ROWS = 40


def _bench_table(df: pd.DataFrame, missing: str | None = None) -> pd.DataFrame:
    """The first BENCH_TABLE_ROWS rows as text; NaN reads "not run" unless a `missing` text says what it means;
    integer columns (batch, n, dof) stay exact."""
    fmt = cell if missing is None else (lambda x: cell(x, missing))
    head = df.head(BENCH_TABLE_ROWS)
    return pd.DataFrame({c: head[c].astype(str) if pd.api.types.is_integer_dtype(head[c]) else head[c].map(fmt)
                         for c in head.columns}).astype(str)


def speed_appendix(res: Results, out_dir: Path) -> list[Section]:
    """Every unit's training throughput (or time) against its claim's metric, a figure per claim."""
    s = Section("Speed against error per unit")
    s.add(Para("Each point is one unit (claim x framework x model x seed): training throughput (or training "
               "time) against the claim's metric; colour per model, marker per framework. Lower error and "
               "higher throughput are better."))
    any_fig, skipped = False, []
    for claim in res.claims:
        metric, units = claim.get("metric"), res.usable(claim["id"])
        rel = f"figures/{slug(claim['id'])}_speed_error.png"
        why = FS.degenerate(units, metric) if metric and units else ""
        if why and FS.speed_points(units, metric):
            skipped.append(f"{claim['id']}: {why}")
        elif metric and FS.speed_error(units, metric, out_dir / rel, higher_better=bool(claim.get("pooled"))):
            any_fig = True
            way = "higher" if claim.get("pooled") else "lower"
            s.add(Figure(rel, f"{claim['id']}: speed against {metric}, one point per unit.",
                         [f"units/{claim['id']}/<framework>/<model>/seed<k>/result.json"],
                         shows=f"{metric} ({way} is better) against {FS.speed_points(units, metric)[0][1][0]}"))
    if skipped:
        s.add(Para("Not drawn, the figure being empty of information: " + "; ".join(skipped) + "."))
    if not any_fig:
        s.add(Para(f"Units with throughput and error: {NOT_RUN}."))
    return [s]


def speed_sections(res: Results, out_dir: Path) -> list[Section]:
    s = Section("Speed against error")
    s.add(Para("Each claim's page shows its work-precision figure (held-out loss against training samples and "
               "time); every unit's throughput against its claim's metric is in the appendix."))
    cheap = cheapest_table(res)
    if cheap is not None:
        s.add(Table(f"Cheapest model within {TOLERANCE:g}x of the best error, per claim", cheap,
                    ["units/*/*/*/seed*/result.json"],
                    note="Cost: mean training throughput over seeds (samples/s; else training time). Only models "
                         "past their competence bar count: one that learned nothing is never recommended."))
    else:
        s.add(Para(f"Cheapest model per system: {NOT_RUN} (or no model past its competence bar)."))
    b = Section("Speed study (lagbench bench)", level=2)
    if not res.bench and res.machine is None:
        b.add(Para(f"Speed study: {NOT_RUN} (no bench/ files)."))
    if FS.bench_speed_error(res.bench.get("inference"), out_dir / "figures/bench_inference.png"):
        b.add(Figure("figures/bench_inference.png", "Inference throughput against error per system "
                     "(colour: model/formulation; marker: framework).", ["bench/inference.csv"],
                     shows="error (the bench metric) against inference throughput (samples/s)"))
    bc = bench_cheapest_table(res)
    if bc is not None:
        b.add(Table(f"Cheapest model within {TOLERANCE:g}x of the best inference error, per system", bc,
                    ["bench/inference.csv"]))
    if FS.bench_scaling(res.bench.get("scaling"), out_dir / "figures/bench_scaling.png"):
        b.add(Figure("figures/bench_scaling.png", "Cost per evaluation against size, per formulation.",
                     ["bench/scaling.csv"], shows="seconds per evaluation against size n"))
    for name, title in (("training", "Training throughput"), ("rollout", "Rollout cost and error per solver "
                                                                        "(truth and learned models)"),
                        ("members", "Many seeds for the price of one: K models trained as one program against one "
                                    "alone (the restarts' scouting phase; cost_vs_one: wall time over one model's)")):
        if name in res.bench:
            b.add(Table(title, _bench_table(res.bench[name]), [f"bench/{name}.csv"]))
    if "latency" in res.bench:
        cols = ["model", "method", "framework", "dtype", "mode", "dispatch", "evals_per_s"]
        b.add(Table("Single-sample latency (online control): evaluations per second, one core",
                    _bench_table(res.bench["latency"][cols]), ["bench/latency.csv"],
                    note="compile_single: JAX `models.jax.compiled`, one XLA dispatch per call; PyTorch "
                         "`models.torch.compiled` (torch.export + AOTInductor, parameters as constants), one call "
                         "into a compiled library; frozen: parameters compiled in as constants; sync: JAX's CPU "
                         "dispatch in the calling thread."))
    if "control_rate" in res.bench:
        cr = res.bench["control_rate"]
        cols = [c for c in ["model", "framework", "mode", "ticks", "mean_us", "median_us", "p99_us", "rate_hz_mean",
                            "rate_hz_p99", "fits_500hz_mean", "fits_500hz_p99", "hidden", "batch"] if c in cr.columns]
        t = _bench_table(cr[cols])
        for c in ("fits_500hz_mean", "fits_500hz_p99"):
            t[c] = t[c].str.lower().map({"true": "yes", "false": "no"}).fillna(t[c])
        b.add(Table("Control-loop rate on one core (the DeLaN paper's robot: 500 Hz)", t, ["bench/control_rate.csv"],
                    note="Per tick of the two-link arm's computed-torque loop on one thread, the model's compute "
                         "in microseconds (the feed-forward call; with learning also the replay-buffer write and "
                         "the optimiser step on a minibatch of `batch`, as `lagbench online`; the simulated plant "
                         "not counted), rate_hz = 1e6 / that time, and fits_500hz: below the 2 ms period."))
    _train_target(b, res.bench, "bench", out_dir, "Samples to reach held-out L1 thresholds (double-pendulum LNN; "
                  "paper: 7.3e-2 at ~3e8, a training loss; its held-out value was 6.9e-2), the speed study's budget")
    _train_target(b, res.train_target, "train_target", out_dir, "Train to target (lagbench train-target): samples "
                  "to reach held-out L1 thresholds, double-pendulum LNN (paper: 7.3e-2 at ~3e8, a training loss; its "
                  "held-out value was 6.9e-2; target: within 3e7)")
    _distribution(b, res.train_target.get("distribution"))
    targets = _targets_table(res.root / "bench" / "targets.json")
    if targets is not None:
        b.add(Table("Speed targets: measured against the target", targets, ["bench/targets.json"]))
    g = _gpu_section(res, out_dir)
    return [s, b] + ([g] if g is not None else [])


def _gpu_section(res: Results, out_dir: Path) -> Section | None:
    """bench_gpu/ (lagbench bench --gpu): its own machine, figures and tables, never mixed with bench/."""
    if not res.bench_gpu and res.machine_gpu is None:
        return None
    g = Section("Speed study on a GPU (lagbench bench --gpu)", level=2)
    m = res.machine_gpu or {}
    g.add(Para(f"Machine: GPU {m.get('gpu') or m.get('torch_gpu') or 'not recorded'}, host CPU "
               f"{m.get('cpu', 'not recorded')} ({m.get('cores', '?')} cores); commit {m.get('commit')}, "
               f"{m.get('date')}; JAX {(m.get('versions') or {}).get('jax')}, PyTorch "
               f"{(m.get('versions') or {}).get('torch')}. Both frameworks on the same GPU with full float32 "
               "matrix products (no TF32); PyTorch eager, JAX jit. Figures from this machine are compared with "
               "the CPU study's only as ratios, in the table below."))
    if FS.bench_speed_error(res.bench_gpu.get("inference"), out_dir / "figures/bench_gpu_inference.png"):
        g.add(Figure("figures/bench_gpu_inference.png", "GPU: inference throughput against error per system "
                     "(colour: model/formulation; marker: framework).", ["bench_gpu/inference.csv"],
                     shows="error (the bench metric) against inference throughput (samples/s)"))
    bc = bench_cheapest_table(res, gpu=True)
    if bc is not None:
        g.add(Table(f"GPU: cheapest model within {TOLERANCE:g}x of the best inference error, per system", bc,
                    ["bench_gpu/inference.csv"]))
    both = gpu_vs_cpu_table(res)
    if both is not None:
        g.add(Table("Inference on the GPU against the CPU study (each framework's fastest mode)", both,
                    ["bench/inference.csv", "bench_gpu/inference.csv"],
                    note="GPU / CPU above 1: the GPU is faster. Two machines: the ratio says which hardware a "
                         "use needs, not how fast either framework is."))
    if FS.bench_scaling(res.bench_gpu.get("scaling"), out_dir / "figures/bench_gpu_scaling.png"):
        g.add(Figure("figures/bench_gpu_scaling.png", "GPU: cost per evaluation against size, per formulation.",
                     ["bench_gpu/scaling.csv"], shows="seconds per evaluation against size n"))
    for name, title in (("training", "GPU: training throughput"), ("fast_paper", "GPU: LNN fast against paper "
                                                                               "formulation (3 x 600, batch 4096)")):
        if name in res.bench_gpu:
            g.add(Table(title, _bench_table(res.bench_gpu[name], missing="-"), [f"bench_gpu/{name}.csv"]))
    targets = _targets_table(res.root / "bench_gpu" / "targets.json")
    if targets is not None:
        g.add(Table("GPU: the speed targets (set for the CPU study) measured on the GPU", targets,
                    ["bench_gpu/targets.json"],
                    note="The fraction of the matrix-product rate uses XLA's GPU cost analysis, which counts "
                         "about a quarter of the FLOPs its CPU analysis counts for the same fast LNN: it is not "
                         "comparable with the CPU fraction."))
    return g


def _train_target(b: Section, tables: dict, folder: str, out_dir: Path, title: str) -> None:
    """The train-to-target table of FOLDER/train_target.csv and the curve of FOLDER/train_target_log.csv."""
    tt = tables.get("train_target")
    if tt is None:
        return
    cols = [c for c in ["protocol", "model", "seed", "hidden", "budget", "threshold", "samples_to_reach",
                        "wall_s_to_reach", "best_l1", "final_l1", "hessian_rel_err", "skipped_steps", "samples_per_s",
                        "extrapolated_samples"]
            if c in tt.columns]
    b.add(Table(title, _bench_table(tt[cols], missing="-"), [f"{folder}/train_target.csv"], note=TRAIN_TARGET_NOTE))
    fig = f"figures/{folder}_train_target.png"
    if FS.train_target_curve(tables.get("train_target_log"), out_dir / fig):
        b.add(Figure(fig, "Held-out L1 against training samples, per protocol (log-log: the axis starts at the "
                          "first logged point, not at zero).", [f"{folder}/train_target_log.csv"],
                     shows="heldout_l1 of q̈ against training samples"))


def _distribution(b: Section, d: pd.DataFrame | None) -> None:
    """train_target/distribution.csv (`lagbench train-target --runs N`): per protocol, the runs that reached
    held-out L1 0.069 and the median and range of their samples and training seconds, then every run."""
    if d is None or not len(d):
        return
    rows = []
    for (name, split), g in d.groupby(["protocol", "split"], sort=False):
        hit = g[g["reached"].astype(str).str.lower() == "true"]
        rows.append({"protocol": name, "split": split, "reached": f"{len(hit)} of {len(g)}",
                     **{f"{k}_{f}": getattr(hit[k], f)() if len(hit) else None
                        for k in ("wall_s_to_reach", "samples_to_reach") for f in ("median", "min", "max")}})
    b.add(Table("Time to the paper's held-out L1 0.069 over independent runs (lagbench train-target --runs N): "
                "median and range over the runs that reached it", _bench_table(pd.DataFrame(rows), missing="-"),
                ["train_target/distribution.csv"],
                note="Each run its own inits (no two runs share one) and batches; wall seconds count training "
                     "steps only (compiling and the held-out evaluations excluded); a run that did not reach the "
                     "target within the budget counts in the runs, not in the median. load_15min_end: the machine's "
                     "15-minute load average when the run ended (its own training threads included; cpus: the "
                     "machine's CPU count), so a time says how busy the machine was."))
    b.add(Table("Time to held-out L1 0.069, every run", _bench_table(d.drop(columns=["threshold"], errors="ignore"),
                                                                     missing="-"), ["train_target/distribution.csv"]))


TRAIN_TARGET_NOTE = (
    "samples_to_reach '-': not reached within the budget; with restarts each scout's end-of-scout held-out "
    "evaluation counts, at the samples of the whole scouting (so loose thresholds read as reached when it ends). "
    "extrapolated_samples is a power-law extrapolation of "
    "the best-so-far curve, not a measurement ('-': reached, or a flat curve; inf: beyond 1000 x 3e8 samples). "
    "restarts: the variant scouting 8 inits and continuing the one with the lowest training loss (seed: the one "
    "chosen); its samples count every scout. restarts_fast: the same scouts, the chosen one continued at batch "
    "256 and peak 2e-3. restarts_halved: restarts_fast over 16 "
    "inits, the 4 lowest at half the scout going on to its end (successive halving; the full profile's "
    "double-pendulum protocol). wall_s_to_reach: seconds "
    "of training steps to the threshold (compiling and evaluations excluded). baseline_reference: the plain MLP "
    "on the variant's protocol, for scale. hessian_rel_err: median relative distance of the final LNN's velocity Hessian from the true mass "
    "matrix times one best scale (0: the true Lagrangian up to its symmetries). skipped_steps: steps the "
    "gradient-spike guard skipped (`replication.training.spike_guard`).")


def _targets_table(path: Path) -> pd.DataFrame | None:
    """One row per target of bench/targets.json: name, met, and its scalar measured values."""
    import json

    try:
        targets = json.loads(path.read_text())["targets"]
    except (OSError, ValueError, KeyError, TypeError):
        return None
    rows = []
    for name, t in targets.items():
        if not isinstance(t, dict):
            continue
        values = "; ".join(f"{k} {('yes' if v else 'no') if isinstance(v, bool) else cell(v)}"
                           for k, v in t.items() if k != "met" and isinstance(v, int | float | str))
        rows.append({"target": name, "met": "yes" if t.get("met") else "no", "measured": values})
    return pd.DataFrame(rows) if rows else None
