"""`lagbench tune`: its command line (the search itself is `tune.py`)."""
from __future__ import annotations

from lagbench import options
from lagbench.replication.claims.base import PROFILES


def _num(v) -> str:
    return "-" if v is None else f"{v:.4g}"


def cmd_tune(args):
    from lagbench.replication.tuning.tune import tune

    frameworks = options.frameworks(args.frameworks)
    seeds = options.seeds_or_count(args)   # a count, the seeds themselves, or None (the claim's)
    ledger = tune(args.claim, profile=args.profile, n_configs=args.configs,
                  n_seeds=seeds if isinstance(seeds, int) else None, seeds=None if isinstance(seeds, int) else seeds,
                  frameworks=frameworks, out=args.out or f"results/tune/{args.claim}_{args.profile}",
                  progress=not args.quiet, record=args.record, jobs=args.jobs, confirm=args.confirm, dry_run=args.dry_run,
                  widths=[x for x in args.widths.split(",") if x.strip()] if args.widths else None)
    if ledger is None:
        return 0
    for label, m in ledger["models"].items():
        scores = ", ".join(f"{k}: {_num(v)}" for k, v in m["scores"].items())
        confirmed = ("" if not m["confirmation"] else " confirmed on seeds "
                     + ",".join(map(str, m["confirm_seeds"])) + " ("
                     + ", ".join(f"{k}: {_num(v)}" for k, v in m["confirmation"].items()) + ")")
        print(f"{label:<22} chose config {m['chosen']} {m['chosen_knobs']} of {m['configs_tried']} "
              f"({scores}){confirmed}")
    if ledger.get("edge_stopped"):
        print("edge step bounded (" + ", ".join(f"{k} at most x{v:g}" for k, v in ledger["edge_limits"].items())
              + ", every model alike): not tried " + ", ".join(f"lr x{p['lr']:.3g} width x{p['width']:g}"
                                                               for p in ledger["edge_stopped"]))
    c = ledger["compute"]
    print(f"compute: {c['units']} units, {c['train_s'] / 3600:.2f} h of training")
    return 0


def add_command(sub) -> None:
    s = sub.add_parser("tune", help="search every model of a claim alike on the development split",
                       description="The declared search for every model of a claim, on the development seeds and "
                       "draws: every combination of peak rate x 1/3, 1, 3 and widths x 1/2, 1, 2 (budget, restarts "
                       "and input scaling as registered), one step further where a model's best lies on an edge "
                       "(tried by every model alike), then the best and the registered setting confirmed on 3 "
                       "development seeds; scored by the metric the claim's verdict reads (a pace study: by its "
                       "pace, one configuration for all its arms). Writes OUT/ledger.json and OUT/ledger.csv. It "
                       "never reads the test split and never changes a claim: a ledger's choices become the "
                       "claim's protocol when adopted (python -m lagbench.replication.tuning.adopt OUT/ledger.json) and "
                       "registered.")
    s.add_argument("--claim", required=True, help="a claim id (see `lagbench list`)")
    s.add_argument("--profile", default="quick", choices=PROFILES, help="the budget to tune at (default: quick)")
    s.add_argument("--record", help="a CSV file of finished units (one small row each): appended to as units "
                   "finish and read back on a rerun, so a search resumes from it on any machine (default: none)")
    s.add_argument("--configs", type=int, help="a partial search for trials: the first N configurations only, no "
                   "edge step and no confirmation; no claim may adopt it (default: the whole search)")
    s.add_argument("--widths", help="a width sweep for trials instead of the search: comma-separated multipliers "
                   "of the registered widths (e.g. 2,4,8), each at the registered rate, every model alike")
    options.add_seeds(s, "how many development seeds, 0.., each configuration trains on (default: 1; a pace "
                      "study: its cohort of 8)", "the development seeds themselves, comma- or space-separated, e.g. "
                      "0,1 (a lone number without a comma is read as --n-seeds until the next release; one seed: "
                      "5,) (default: seed 0; a pace study: 0 to 7)")
    s.add_argument("--confirm", type=int, default=3,
                   help="development seeds the chosen and the registered configuration are compared on (default: 3)")
    s.add_argument("--frameworks", default="jax", help="comma-separated: jax, torch (default: jax)")
    s.add_argument("--out", help="results folder (default: results/tune/<claim>_<profile>)")
    s.add_argument("--jobs", type=int, default=1, help="worker processes: the models of a configuration (and a "
                   "framework's or seed's units) train side by side, one CPU thread each; their scores differ from one "
                   "process's in float32 rounding only (default: 1)")
    s.add_argument("--dry-run", action="store_true", help="print the first stage's trainings and their estimated "
                   "time, and stop")
    s.add_argument("--quiet", action="store_true", help="no progress bars")
    s.set_defaults(func=cmd_tune)
