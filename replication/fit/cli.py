"""The command line of bringing your own data: `lagbench simulate` (here), `fit` (`replication.fit.fit_cli`)
and `evaluate` (`replication.fit.evaluate_cli`), registered on `lagbench.cli`'s parser by `add_commands`.
Every option shows its default in `--help`; bad input is one line naming the option (raised as ValueError,
printed by `cli.main`)."""
from __future__ import annotations

from pathlib import Path

from lagbench.options import show_defaults as _show_defaults
from lagbench.replication.fit.evaluate_cli import _fitted_folder, add_evaluate, evaluation_line
from lagbench.replication.fit.fit_cli import add_fit

__all__ = ["add_commands", "cmd_simulate", "evaluation_line", "_fitted_folder"]   # the last two: for the tests


def cmd_simulate(args):
    from lagbench.files.results import write_csv
    from lagbench.replication.fit.simulate import simulate

    path = Path(args.out)
    if path.suffix != ".csv":
        raise ValueError(f"--out {path}: give a .csv file name")
    df = simulate(args.system, args.trajectories, args.duration, args.rate, args.noise, args.seed, args.velocities,
                  args.dropped, args.decimals, settings=args.set)
    write_csv(path, df)
    print(f"{args.trajectories} trajectories of {args.system}, {len(df)} rows, written to {path}")


def add_commands(sub) -> None:
    s = sub.add_parser("simulate", help="noisy trajectories of a system, as a trajectory file "
                       "for fit / evaluate", description="Integrate trajectories of a system of `systems/` (float64, "
                       "tight tolerances) from states of its own distribution and add Gaussian noise.")
    s.add_argument("--system", default="pendulum", help="a system name, see `lagbench list`")
    s.add_argument("--trajectories", type=int, default=8, help="how many trajectories")
    s.add_argument("--duration", type=float, default=5.0, help="seconds per trajectory")
    s.add_argument("--rate", type=float, default=50.0, help="samples per second")
    s.add_argument("--noise", type=float, default=0.01, help="standard deviation of the noise added to q (and qdot)")
    s.add_argument("--velocities", action="store_true", help="also write noisy velocities qdot0..")
    s.add_argument("--dropped", type=float, default=0.0, help="share of samples left out at random, as a logger "
                   "that drops frames (never a trajectory's first or last)")
    s.add_argument("--decimals", type=int, help="round the written times to this many decimals, as a real log "
                   "(default: full precision)")
    s.add_argument("--seed", type=int, default=0, help="seed of the initial states and the noise")
    s.add_argument("--set", action="append", metavar="NAME=VALUE", help="a system parameter or option, e.g. "
                   "friction=0.2 (viscous friction of the pendulums and the arm; repeatable; an unknown name "
                   "lists the system's parameters)")
    s.add_argument("--out", required=True, help="required: the .csv file to write, e.g. data/train.csv (none is "
                   "assumed, so that no simulation writes over another's file)")
    s.set_defaults(func=cmd_simulate)
    _show_defaults(s)
    add_fit(sub)
    add_evaluate(sub)
