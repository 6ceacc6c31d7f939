"""`lagbench control`: its command line (the study itself is `control.py`; the four-joint arm's, which fits its
own models, `arm4_control.py`).

Every option is checked before any work (a one-line error naming it). `--system two_link_arm` (the default)
tracks with claim 9's models in the results folder `--trained-from` (default: `--out`) and writes OUT/control/;
any other arm of `systems.arm_data.ARMS` fits its models first and writes OUT/control_<system>/ (`--steps`,
`--seeds`, `--frameworks` are its fit options, refused for the two-link arm, whose models are claim 9's; and
`--trained-from` is the two-link arm's alone). `--results` is the old spelling of `--out`."""
from __future__ import annotations

from pathlib import Path

from lagbench import options

TWO_LINK = "two_link_arm"


def _fit_options(args) -> dict:
    from lagbench.replication.studies import arm4_control as A
    from lagbench.replication.studies.robustness_cli import _steps

    return {"steps": _steps(args.steps or str(A.STEPS)), "framework": args.framework or "jax",
            "seeds": options.seeds(args.seeds or ["0"])}


def _check(args) -> dict:
    from lagbench.systems.arm_data import ARMS

    if args.system not in ARMS:
        raise ValueError(f"--system {args.system}: expected one of {', '.join(ARMS)}")
    if args.references < 1 or not args.duration > 0:
        raise ValueError(f"--references {args.references} --duration {args.duration}: need at least 1 reference "
                         "and a duration above 0 s")
    if args.system == TWO_LINK:
        given = [o for o, v in (("--steps", args.steps), ("--seeds", args.seeds), ("--frameworks", args.framework))
                 if v is not None]
        if given:
            raise ValueError(f"{', '.join(given)}: fit options of the arms other than {TWO_LINK}, whose models are "
                             f"claim 9's trained units in --trained-from")
        trained = Path(args.trained_from or args.out)
        if not trained.is_dir():
            raise ValueError(f"--trained-from {trained}: no such folder; give a results folder holding claim 9's "
                             f"units (the --out of `lagbench run --claims delan_arm`)")
        return {}
    if args.trained_from is not None:
        raise ValueError(f"--trained-from: the {TWO_LINK}'s option (claim 9's models); --system {args.system} fits "
                         f"its own")
    return _fit_options(args)


def cmd_control(args):
    from tqdm.auto import tqdm

    from lagbench.files.results import output_folder

    fit = _check(args)
    two_link = args.system == TWO_LINK
    folder = output_folder(Path(args.out) / ("control" if two_link else f"control_{args.system}"), "--out")
    bar = tqdm(desc="lagbench control", unit="controller", disable=args.quiet)
    try:
        if two_link:
            from lagbench.replication.studies.control import write_study

            df = write_study(Path(args.trained_from or args.out), folder, n_refs=args.references,
                             duration=args.duration, progress=lambda _: bar.update())
        else:
            from lagbench.replication.studies.arm4_control import write_study

            df = write_study(folder, n_refs=args.references, duration=args.duration,
                             progress=lambda what: (bar.set_postfix_str(what), bar.update()), **fit)
    finally:
        bar.close()
    cols = ["family", "controller", "framework", "seed", "track_mse", "ratio_to_pd", "n_diverged"]
    print(df[cols].to_string(index=False))
    print(f"written to {folder}")


def add_command(sub) -> None:
    s = sub.add_parser("control", help="closed-loop tracking of the two-link arm with claim 9's learned inverse models "
                                       "(writes OUT/control/), or of the four-joint arm with models it fits "
                                       "(OUT/control_four_joint_arm/)",
                       description="Computed-torque control at 500 Hz of the SymPy two-link arm (RK4 plant, 4 steps a "
                       "period) on references no model trained on (the unseen family, the training family twice "
                       "as fast), with each full-data DeLaN and feed-forward net of claim 9 in --trained-from, the "
                       "true inverse dynamics and PD alone (gains KP 20, KD 2 sqrt(20)). Writes OUT/control/"
                       "tracking.csv and traces.npz. With --system four_joint_arm it first fits DeLaN and the "
                       "feed-forward net to the four-joint arm's training family under one budget (--steps, "
                       "--seeds, --frameworks) and tracks the same families on the four-joint arm, writing "
                       "OUT/control_four_joint_arm/ (tracking.csv, traces.npz, study.json, data/, fits/).")
    options.add(s, "--out", "--results", why="the folder written; claim 9's units are read from --trained-from, "
                "--out unless given", default="results/quick", help="results folder; writes OUT/control/ "
                "(OUT/control_<system>/ for another arm) (default: results/quick, which `lagbench report` reads "
                "unless given --results)")
    s.add_argument("--trained-from", metavar="RESULTS", help="two-link arm: a results folder holding claim 9's "
                   "trained units, whose models track (default: --out)")
    s.add_argument("--system", default=TWO_LINK, help="the arm: two_link_arm or four_joint_arm "
                   "(default: two_link_arm)")
    s.add_argument("--references", type=int, default=8, help="reference trajectories per family (default: 8)")
    s.add_argument("--duration", type=float, default=4.0, help="seconds per reference (default: 4)")
    s.add_argument("--steps", default=None, help="four-joint arm: optimiser steps of each model "
                   "(default: 3000)")
    s.add_argument("--seeds", nargs="+", default=None, help="four-joint arm: model seeds, comma- or "
                   "space-separated (default: 0)")
    options.add(s, "--frameworks", "--framework", dest="framework", help="four-joint arm: the one framework "
                "its models train in, jax or torch (default: jax)")
    options.check(s, "framework", options.one_framework("control"))
    s.add_argument("--quiet", action="store_true", help="no progress bar")
    s.set_defaults(func=cmd_control)
