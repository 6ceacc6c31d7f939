"""`lagbench train-target`: the train-to-target study alone (`speedstudy.train_target_run`), at any budget."""
from __future__ import annotations

import argparse
from pathlib import Path

from replication.renamed import renamed
from replication.training.device import HELP as DEVICE_HELP

HELDOUT_STATES = 4096


def cmd_train_target(args):
    from replication.fit.options import widths
    from speedstudy.train_target_run import check_names, run_study

    heldout = renamed("train-target", args.heldout_states, args.heldout_old, HELDOUT_STATES, "--heldout-states", "--heldout",
                      "in `fit`, --holdout-fraction is a fraction of the rows")
    if heldout < 1 or args.seed < 0:
        raise ValueError(f"--heldout-states takes an integer >= 1 and --seed one >= 0; got {heldout} and {args.seed}")
    names = [x.strip() for x in args.protocols.split(",") if x.strip()] if args.protocols else None
    hidden = list(widths(args.hidden))
    check_names(names)  # here too, so that --out is not made for nothing
    from replication.results import output_folder
    from replication.training import device

    where = device.apply(args.device, ("jax",))["jax"]   # the study trains in JAX
    folder = output_folder(Path(args.out) / "train_target", "--out")
    with device.placed("jax", where):
        df = run_study(folder, args.budget, hidden, heldout, names=names, seed=args.seed,
                       progress=not args.quiet)
    per = df.drop_duplicates("protocol")[["protocol", "budget", "best_l1", "final_l1", "seed", "hessian_rel_err",
                                           "skipped_steps", "samples_per_s"]]
    print(per.to_string(index=False))
    print(df.pivot(index="protocol", columns="threshold", values="samples_to_reach").to_string())
    print(f"written to {folder}")


def add_train_target(sub) -> None:
    s = sub.add_parser("train-target", help="the train-to-target study alone, at any budget (writes "
                                            "OUT/train_target/train_target.csv and its log, the log after every "
                                            "held-out evaluation, and each protocol's final model as "
                                            "<protocol>.npz with <protocol>.spec.json)")
    s.add_argument("--out", default="results/train_target", help="results folder; writes OUT/train_target/ "
                   "(default: results/train_target)")
    s.add_argument("--budget", type=float, default=5e5, help="training samples per protocol (default 5e5; the "
                                                             "issue's target is 3e7)")
    s.add_argument("--hidden", default="64,64,64", help="MLP widths (default 64,64,64; the paper's 600,600,600)")
    s.add_argument("--heldout-states", type=int, default=HELDOUT_STATES, help="held-out states, >= 1 (default 4096)")
    # the old spelling: in `fit`, --holdout-fraction is a fraction of the rows
    s.add_argument("--heldout", dest="heldout_old", type=int, help=argparse.SUPPRESS)
    s.add_argument("--protocols", help="comma-separated: original_scaled, variant, restarts, restarts_fast, "
                                       "restarts_halved, baseline_reference (default all)")
    s.add_argument("--seed", type=int, default=0, help="init seed (restarts: this seed and the next 7, 15 for "
                                                            "restarts_halved; default 0)")
    s.add_argument("--quiet", action="store_true", help="no progress bar")
    s.add_argument("--device", default="auto", choices=("auto", "cpu", "gpu"), help=DEVICE_HELP)
    s.set_defaults(func=cmd_train_target)
