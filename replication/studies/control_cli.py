"""`lagbench control`: its command line (the study itself is `control.py`)."""
from __future__ import annotations

from pathlib import Path


def cmd_control(args):
    from tqdm.auto import tqdm

    from replication.results import output_folder
    from replication.studies.control import write_study

    results = Path(args.results)
    if not results.is_dir():
        raise ValueError(f"--results {results}: no such folder")
    if args.references < 1 or not args.duration > 0:
        raise ValueError(f"--references {args.references} --duration {args.duration}: need at least 1 reference "
                         "and a duration above 0 s")
    folder = output_folder(results / "control", "--results")
    bar = tqdm(desc="lagbench control", unit="controller", disable=args.quiet)
    try:
        df = write_study(results, folder, n_refs=args.references, duration=args.duration,
                         progress=lambda _: bar.update())
    finally:
        bar.close()
    cols = ["family", "controller", "framework", "seed", "track_mse", "ratio_to_pd", "n_diverged"]
    print(df[cols].to_string(index=False))
    print(f"written to {folder}")


def add_command(sub) -> None:
    s = sub.add_parser("control", help="closed-loop tracking of the two-link arm with claim 9's learned inverse models "
                                       "(writes RESULTS/control/ for the report)",
                       description="Computed-torque control at 500 Hz of the SymPy two-link arm (RK4 plant, 4 steps a "
                       "period) on references no model trained on (the unseen family, the training family twice "
                       "as fast), with each full-data DeLaN and feed-forward net of claim 9 in RESULTS, the true "
                       "inverse dynamics and PD alone (gains KP 20, KD 2 sqrt(20)). Writes RESULTS/control/"
                       "tracking.csv and traces.npz.")
    s.add_argument("--results", default="results/quick", help="a results folder holding claim 9's units "
                   "(default: results/quick)")
    s.add_argument("--references", type=int, default=8, help="reference trajectories per family (default: 8)")
    s.add_argument("--duration", type=float, default=4.0, help="seconds per reference (default: 4)")
    s.add_argument("--quiet", action="store_true", help="no progress bar")
    s.set_defaults(func=cmd_control)
