"""`lagbench verify`: its command line (the check itself is `replication.run.verify`).

Exit status 0 when every value of every retrained unit is identical or within its tolerance, 1 otherwise
(a difference past the tolerance, or a unit that could not be retrained); the differences are printed.
"""
from __future__ import annotations

from lagbench.replication.training.device import HELP as DEVICE_HELP


def cmd_verify(args):
    from lagbench.options import frameworks, names
    from lagbench.replication.run.verify import summary, verify
    from lagbench.replication.training import device

    device.apply(args.device, ("jax", "torch"))
    only = {"claims": args.claims and names(args.claims), "models": args.models and names(args.models),
            "frameworks": args.frameworks and frameworks(args.frameworks)}
    rows = verify(args.results, args.units, seed=args.seed, jobs=args.jobs, progress=not args.quiet, only=only)
    print(summary(rows))
    print(f"written to {args.results}/verify/verify.csv")
    return 0 if rows["outcome"].isin(("identical", "within", "timing")).all() else 1


def add_command(sub) -> None:
    s = sub.add_parser("verify", help="retrain some finished units of a results folder from scratch and compare "
                       "them with the stored ones (writes RESULTS/verify/verify.csv)",
                       description="Pick --units finished units of the results folder at random (seeded by --seed), "
                       "retrain each from scratch in a temporary folder with the same protocol, seed and framework, "
                       "and compare every metric, the status and the final training loss with the stored result: "
                       "identical bit for bit where retrained on the same kind of CPU with the same library "
                       "versions, else within a stated relative tolerance (float32 training is chaotic at the "
                       "level of rounding), every difference printed. Adds its rows to RESULTS/verify/verify.csv, "
                       "which `lagbench report` summarises (how many units, where and when).")
    s.add_argument("--results", default="runs/full", help="a folder written by `lagbench run` (the run of record: "
                   "docs/store.md); read, and RESULTS/verify/verify.csv written into it (default: runs/full)")
    s.add_argument("--units", type=int, default=3, help="how many units to retrain (default: 3)")
    s.add_argument("--seed", type=int, default=0, help="the seed of the random choice of units: the same seed "
                   "picks the same units (default: 0)")
    s.add_argument("--claims", help="comma-separated claim ids: draw the units among these claims' only, e.g. "
                   "dp_loss for a double-pendulum training (default: every claim)")
    s.add_argument("--frameworks", help="comma-separated: jax, torch: draw among these frameworks' units only "
                   "(default: both)")
    s.add_argument("--models", help="comma-separated model labels: draw among these models' units only (default: "
                   "every model)")
    s.add_argument("--jobs", type=int, default=1, help="worker processes for the units a run trained in "
                   "workers, as `lagbench run --jobs` (default: 1)")
    s.add_argument("--quiet", action="store_true", help="no progress bars")
    s.add_argument("--device", default="auto", choices=("auto", "cpu", "gpu"), help=DEVICE_HELP)
    s.set_defaults(func=cmd_verify)
