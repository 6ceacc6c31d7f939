"""`lagbench train-target`: the train-to-target study alone (`speedstudy.train_target_run`), at any budget,
on the development or test split, once or as a distribution over --runs independent runs
(`speedstudy.target_distribution`).

Layout: with --runs 1 on the development split, OUT/train_target/ holds the one run's files; otherwise each
run r writes OUT/train_target/run<r>/ (with its inputs.json; a finished run of the same inputs is reused),
and with --runs > 1 OUT/train_target/distribution.csv and distribution.json summarise them."""
from __future__ import annotations

from pathlib import Path

from lagbench import options
from lagbench.replication.training.device import HELP as DEVICE_HELP

HELDOUT_STATES = 4096


def cmd_train_target(args):
    from lagbench.replication.fit.option_values import widths
    from lagbench.replication.run import splits
    from lagbench.speedstudy import target_distribution as dist
    from lagbench.speedstudy.train_target import protocols
    from lagbench.speedstudy.train_target_run import check_names, run_study

    heldout = args.heldout_states
    if heldout < 1 or args.seed < 0:
        raise ValueError(f"--heldout-states takes an integer >= 1 and --seed one >= 0; got {heldout} and {args.seed}")
    names = [x.strip() for x in args.protocols.split(",") if x.strip()] if args.protocols else None
    hidden = list(widths(args.hidden))
    check_names(names)  # here too, so that --out is not made for nothing
    if not args.budget >= 1:
        raise ValueError(f"the train-target budget must be at least 1 sample, got {args.budget!r}")
    split = splits.get(args.split)
    seeds = dist.init_seeds(names or list(protocols(1000, 1)), split, args.seed, args.runs)   # checks --runs
    from lagbench.files.results import output_folder
    from lagbench.replication.training import device

    where = device.apply(args.device, ("jax",))["jax"]   # the study trains in JAX
    folder = output_folder(Path(args.out) / "train_target", "--out")
    with device.placed("jax", where):
        if args.runs == 1 and split is splits.DEV:   # one development run: its files in OUT/train_target/
            df = run_study(folder, args.budget, hidden, heldout, names=names, seed=seeds[0],
                           progress=not args.quiet)
        else:
            df = dist.run_many(folder, args.budget, hidden, heldout, names, split, args.seed, args.runs,
                               progress=not args.quiet)
    if args.runs > 1:
        _, summary = dist.distribution(folder, df, split, args.budget, n_heldout=heldout, hidden=hidden)
        print(f"held-out L1 <= {dist.TARGET:g} on the {split.name} split (median, min, max over the runs that "
              f"reached it):")
        print(dist.summary_table(summary).to_string(index=False))
        print(f"written to {folder} (distribution.csv, distribution.json, run0..run{args.runs - 1})")
        return
    per = df.drop_duplicates("protocol")[["protocol", "budget", "best_l1", "final_l1", "seed", "hessian_rel_err",
                                           "skipped_steps", "samples_per_s"]]
    print(per.to_string(index=False))
    print(df.pivot(index="protocol", columns="threshold", values="samples_to_reach").to_string())
    print(f"written to {folder}")


def add_train_target(sub) -> None:
    s = sub.add_parser("train-target", help="the train-to-target study alone, at any budget (writes "
                                            "OUT/train_target/)",
                       description="Train the double-pendulum LNN under each protocol of the train-to-target study "
                       "for --budget samples and record the samples and seconds each needs to reach held-out L1 "
                       "thresholds, the tightest being the original code's held-out L1 of 0.069 (the target: reach "
                       "it within 3e7 samples, a tenth of the 3e8 the original code consumed). Writes "
                       "OUT/train_target/train_target.csv and its log (after every held-out evaluation) and each "
                       "protocol's final model as <protocol>.npz with <protocol>.spec.json; with --runs > 1 or "
                       "--split test, each run in OUT/train_target/run<r>/, and with --runs > 1 distribution.csv "
                       "and distribution.json.")
    s.add_argument("--out", default="results/train_target", help="results folder; writes OUT/train_target/ "
                   "(default: results/train_target)")
    s.add_argument("--budget", type=float, default=5e5, help="training samples per protocol; the target is 3e7 "
                                                             "(default: 5e5)")
    s.add_argument("--hidden", default="64,64,64", help="MLP widths; the paper's are 600,600,600 (default: "
                   "64,64,64)")
    options.add(s, "--heldout-states", "--heldout", type=int, default=HELDOUT_STATES, why="in `fit`, "
                "--holdout-fraction is a fraction of the rows", help=f"held-out states, >= 1 (default: "
                f"{HELDOUT_STATES})")
    s.add_argument("--protocols", help="comma-separated: original_scaled, variant, restarts, restarts_fast, "
                                       "restarts_halved, baseline_reference (default: all)")
    s.add_argument("--seed", type=int, default=0, help="init seed offset within the split: the first init is the "
                   "split's first seed (dev 0, test 1000) + this (restarts: that seed and the next 7, 15 for "
                   "restarts_halved) (default: 0)")
    s.add_argument("--split", default="dev", help="dev or test: the init seeds (dev 0.., test 1000..) and the "
                   "held-out draw every evaluation reads (dev: the development draw; test: a draw no protocol "
                   "choice has seen); the held-out draw never steers training (default: dev)")
    s.add_argument("--runs", type=int, default=1, help="independent runs of each protocol, >= 1; run r starts at "
                   "init seed offset --seed + r x the inits a protocol scouts (16 restarts_halved, 8 restarts and "
                   "restarts_fast, 1 otherwise), so no two runs share an init; each writes OUT/train_target/run<r>/ "
                   "and a finished run of the same inputs is reused; with > 1, distribution.csv and "
                   "distribution.json hold the samples and seconds to held-out L1 0.069 per run (default: 1)")
    s.add_argument("--quiet", action="store_true", help="no progress bar")
    s.add_argument("--device", default="auto", choices=("auto", "cpu", "gpu"), help=DEVICE_HELP)
    s.set_defaults(func=cmd_train_target)
