"""`lagbench robustness`: its command line (the study is `robustness.py`, its scenes `robustness_scenes.py`).

Every option is checked before any work (a one-line error naming it); the command writes only into
OUT/robustness/ (besides the suite's training cache, `$LAGBENCH_CACHE`)."""
from __future__ import annotations

from pathlib import Path

from lagbench import options


def _steps(text: str) -> int:
    if not text.strip().isdigit() or int(text) < 1:
        raise ValueError(f"--steps {text}: expected an integer >= 1")
    return int(text)


def _jobs(text: str) -> int:
    if not text.strip().isdigit() or int(text) < 1:
        raise ValueError(f"--jobs {text}: expected an integer >= 1 (worker processes)")
    return int(text)


def cmd_robustness(args):
    from tqdm.auto import tqdm

    from lagbench.files.results import output_folder
    from lagbench.replication.studies import robustness as R

    steps, seeds, jobs = _steps(args.steps), options.seeds(args.seeds), _jobs(args.jobs)
    folder = output_folder(Path(args.out) / "robustness", "--out")
    total = len(R.SCENES) * (2 + len(seeds) * len(R.MODELS))
    bar = tqdm(total=total, desc="lagbench robustness", unit="model", disable=args.quiet)
    try:
        df, rec = R.write_study(folder, framework=args.framework, seeds=seeds, steps=steps, jobs=jobs,
                                progress=lambda what: (bar.set_postfix_str(what), bar.update()))
    finally:
        bar.close()
    cols = ["scene", "model", "seed", "params", "torque_nmse", "track_mse", "torque_ratio_to_ff", "track_ratio_to_ff"]
    print(df[cols].to_string(index=False, float_format=lambda x: f"{x:.3g}"))
    print(rec[["scene", "recommended", "params", "torque_nmse", "best_model", "best_torque_nmse"]].to_string(
        index=False, float_format=lambda x: f"{x:.3g}"))
    print(f"written to {folder}")


def add_command(sub) -> None:
    s = sub.add_parser("robustness", help="DeLaN vs the feed-forward net on arms with friction and noise "
                                          "(writes OUT/robustness/)",
                       description="For each scene (nominal; viscous and Coulomb joint friction; noise on the "
                       "recorded torques; noise on q with qdot and qddot estimated by the suite's filter; two "
                       "magnitudes each) fit DeLaN, DeLaN with a learned dissipation and the feed-forward net to "
                       "the two-link arm's training family under one budget, and score the torque error on the "
                       "unseen family and closed-loop tracking of unseen references on the scene's plant. Writes "
                       "OUT/robustness/scenes.csv, recommendation.csv and advantage.png (see docs/robustness.md).")
    s.add_argument("--out", default="results/quick", help="results folder; writes OUT/robustness/ (default: "
                   "results/quick, which `lagbench report` reads unless given --results)")
    s.add_argument("--steps", default="3000", help="optimiser steps of every model (default: 3000)")
    s.add_argument("--seeds", nargs="+", default=["0"], help="seeds, comma- or space-separated (default: 0)")
    options.add(s, "--frameworks", "--framework", dest="framework", default="jax", help="the one framework every "
                "model trains in: jax or torch (default: jax)")
    options.check(s, "framework", options.one_framework("robustness"))
    s.add_argument("--jobs", default="1", help="worker processes, a scene each at a time (default: 1; the "
                                               "fits are the same in any number of workers up to rounding)")
    s.add_argument("--quiet", action="store_true", help="no progress bar")
    s.set_defaults(func=cmd_robustness)
