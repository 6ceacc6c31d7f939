"""`lagbench tune`: its command line (the search itself is `tune.py`)."""
from __future__ import annotations

from replication.claims.base import PROFILES


def cmd_tune(args):
    from replication.tuning.tune import tune

    frameworks = tuple(x.strip() for x in args.frameworks.split(",") if x.strip()) or ("jax",)
    ledger = tune(args.claim, profile=args.profile, n_configs=args.configs, n_seeds=args.seeds,
                  frameworks=frameworks, out=args.out or f"results/tune/{args.claim}", progress=not args.quiet,
                  widths=[x for x in args.widths.split(",") if x.strip()] if args.widths else None)
    for label, m in ledger["models"].items():
        scores = ", ".join(f"{k}: {'-' if v is None else f'{v:.4g}'}" for k, v in m["scores"].items())
        print(f"{label:<22} chose config {m['chosen']} {m['chosen_knobs']} of {m['configs_tried']} ({scores})")
    return 0


def add_command(sub) -> None:
    s = sub.add_parser("tune", help="search every model of a claim alike on the development split",
                       description="Train every model of a claim under the same declared search (peak rate x 1/3, "
                       "1, 3; widths x 1/2, 1, 2; the registered setting first, then other combinations; budget, "
                       "restarts and input scaling as registered) on the development seeds and draws, score each "
                       "by its development held-out error, and write OUT/ledger.json and OUT/ledger.csv "
                       "(configurations tried and chosen per model). It never reads the test split and never "
                       "changes a claim: a ledger's choices become the claim's protocol when adopted "
                       "(python -m replication.tuning.adopt OUT/ledger.json) and registered.")
    s.add_argument("--claim", required=True, help="a claim id (see `lagbench list`)")
    s.add_argument("--profile", default="quick", choices=PROFILES, help="the budget to tune at (default: quick)")
    s.add_argument("--configs", type=int, default=4,
                   help="configurations per model, the same for every model (default: 4)")
    s.add_argument("--widths", help="a width sweep instead of the search: comma-separated multipliers of the "
                   "registered widths (e.g. 2,4,8), each at the registered rate, the registered setting first, "
                   "every model alike (--configs is then unused)")
    s.add_argument("--seeds", type=int, default=1, help="development seeds per configuration (default: 1)")
    s.add_argument("--frameworks", default="jax", help="comma-separated: jax, torch (default: jax)")
    s.add_argument("--out", help="results folder (default: results/tune/<claim>)")
    s.add_argument("--quiet", action="store_true", help="no progress bars")
    s.set_defaults(func=cmd_tune)
