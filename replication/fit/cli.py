"""The command line of bringing your own data: `lagbench simulate`, `fit` and `evaluate` (registered on
`replication.cli`'s parser by `add_commands`). Every option shows its default in `--help`; bad input is
one line naming the option (raised as ValueError, printed by `cli.main`)."""
from __future__ import annotations

import sys
from pathlib import Path

from replication.fit.rows import HELDOUT, SPLITS
from replication.fit.trajectories import POLYORDER, WINDOW
from replication.training.device import HELP as DEVICE_HELP

DATA_HELP = ("a trajectory file: .csv with columns traj, t, q0..q{d-1} and optional qdot0.., qddot0.., tau0.. "
             "(.npz: arrays traj, t, q, ...), derivatives it lacks estimated by a Savitzky-Golay filter; or a "
             "state file: columns (arrays) q, qdot, qddot and optional tau (format: README)")

HORIZON_HELP = ("seconds from each trajectory's start that the rollouts cover (longer trajectories are rolled "
                "out and scored to there)")


def _show_defaults(parser) -> None:
    """Every option's help ends with its default, unless it states one itself (flags and required ones aside)."""
    for action in parser._actions:
        text = action.help or ""
        if "default" in text or action.required or not action.option_strings or action.nargs == 0:
            continue
        action.help = text + (" (default: none)" if action.default is None else " (default: %(default)s)")


def widths(text: str, option: str = "--hidden") -> tuple:
    """Layer widths from "128,128"; a ValueError naming `option` otherwise (also `lagbench train-target`'s)."""
    try:
        out = tuple(int(x) for x in text.split(","))
    except ValueError:
        out = ()
    if not out or min(out) < 1:
        raise ValueError(f"{option} takes comma-separated layer widths >= 1 such as 128,128; got {text!r}")
    return out


def _scale(text: str):
    if text in ("none", "auto"):
        return None if text == "none" else "auto"
    try:
        return tuple(float(x) for x in text.split(","))
    except ValueError:
        raise ValueError(f"--input-scale takes none, auto or comma-separated numbers such as 1,1,0.3,0.3; got "
                         f"{text!r}") from None


def cmd_simulate(args):
    from replication.fit.simulate import simulate
    from replication.results import write_csv

    path = Path(args.out)
    if path.suffix != ".csv":
        raise ValueError(f"--out {path}: give a .csv file name")
    df = simulate(args.system, args.trajectories, args.duration, args.rate, args.noise, args.seed, args.velocities)
    write_csv(path, df)
    print(f"{args.trajectories} trajectories of {args.system}, {len(df)} rows, written to {path}")


class RolloutBars:
    """tqdm bars for an evaluation's rollouts, one per evaluation set: `bars(label, done, total)`."""

    def __init__(self, quiet: bool, prefix: str):
        self.quiet, self.prefix, self.bars = quiet, prefix, {}

    def __call__(self, label, done, total):
        from tqdm.auto import tqdm

        if label not in self.bars:
            self.bars[label] = tqdm(total=total, desc=f"{self.prefix} rollouts ({label})", unit="sample",
                                    disable=self.quiet)
        bar = self.bars[label]
        bar.update(min(done, total) - bar.n)
        if done >= total:
            bar.close()

    def close(self):
        for bar in self.bars.values():
            bar.close()
        self.bars = {}


def cmd_fit(args):
    from tqdm.auto import tqdm

    from replication.fit.task import LOSS_NAMES, fit
    from replication.training import device

    device.apply(args.device, (args.framework,))   # before anything is written
    bars = []  # made at the first log row, so that a refused option prints one line and nothing else
    rollouts = RolloutBars(args.quiet, f"lagbench fit {args.model}")

    def on_log(row):
        if not bars:
            bars.append(tqdm(total=args.steps, desc=f"lagbench fit {args.model}", unit="step", disable=args.quiet))
        bar = bars[0]
        bar.set_postfix_str(f"training {LOSS_NAMES[args.loss]} {row['loss']:.4g}", refresh=False)
        bar.update(min(int(row["step"]) + 1, bar.total) - bar.n)
        if bar.n >= bar.total:   # closed now, so that its time is the training's, not the evaluation's too
            bar.close()

    try:
        d = fit(args.data, model=args.model, out=args.out, framework=args.framework, steps=args.steps,
                hidden=widths(args.hidden, "--hidden"), batch=args.batch, lr=args.lr, seed=args.seed, loss=args.loss,
                activation=args.activation, weight_decay=args.weight_decay, schedule=args.schedule,
                lr_min_ratio=args.lr_final, delan_eps=args.delan_eps, delan_offset=args.delan_offset,
                angle_wrap=args.angle_wrap, input_scale=_scale(args.input_scale), split=args.split,
                heldout=args.heldout, test=args.test, window=args.window, polyorder=args.polyorder,
                system=args.system, substeps=args.substeps, energy=args.energy, horizon=args.horizon,
                on_log=on_log, on_progress=rollouts)
    finally:
        for bar in bars:
            bar.close()
        rollouts.close()
    folder = Path(args.out) / "units" / "fit" / args.framework / args.model / f"seed{args.seed}"
    if d["status"] != "ok":
        print(f"lagbench: fit failed: {d['failure']['message']} (record in {folder})", file=sys.stderr)
        return 1
    again = " (unchanged data and options: the earlier fit)" if d.get("reused") else ""
    value = d.get("final_train_loss") if d["metric"] == "final_train_loss" else d["metrics"].get(d["metric"])
    print(f"ok: {d['metric_label']} {value:.6g}, written to {folder}{again}")


def cmd_evaluate(args):
    from replication.fit.evaluate_file import evaluate

    rollouts = RolloutBars(args.quiet, "lagbench evaluate")
    try:
        done = evaluate(args.model, args.data, out=args.out, framework=args.framework, system=args.system,
                        substeps=args.substeps, window=args.window, polyorder=args.polyorder, energy=args.energy,
                        device=args.device, horizon=args.horizon, on_progress=rollouts)
    finally:
        rollouts.close()
    for d in done:
        m = d["metrics"]
        parts = [f"{k} {m[k]:.4g}" for k in (f"test_{d['protocol']['loss']}", "test_rollout_gmean_err",
                                             "test_learned_energy_drift", "test_energy_err_final") if m.get(k) is not None]
        again = " (the earlier evaluation)" if d.get("reused") else ""
        print(f"{d['model']} ({d['framework']}): {', '.join(parts)}; written to {d['folder']}{again}")


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
    s.add_argument("--seed", type=int, default=0, help="seed of the initial states and the noise")
    s.add_argument("--out", required=True, help="the .csv file to write")
    s.set_defaults(func=cmd_simulate)
    _show_defaults(s)

    s = sub.add_parser("fit", help="train a model on your own data (format: README)",
                       description="Train one model on a data file and write OUT/units/fit/<framework>/<model>/"
                       "seed<k>/ (result.json, train_log.csv, checkpoint.npz, one_step.csv, rollouts.csv), and the "
                       "prepared rows to OUT/data/. Optimiser: Adam; learning rate: the one-cycle cosine of the "
                       "original LNN code (starts at 35 % of --lr, peaks at --lr 37.5 % into training, ends at "
                       "--lr x --lr-final) or constant. A fit of other data or options already there is kept as "
                       "superseded-<time>-seed<k>. Load the model in Python with "
                       "replication.fit.load.load_fitted(folder).")
    s.add_argument("--data", required=True, help=DATA_HELP)
    s.add_argument("--model", required=True, help="lnn | hnn | delan | baseline (lnn and hnn refuse data with tau)")
    s.add_argument("--test", help="a file of the same format evaluated as a whole after training (rollouts from "
                   "each trajectory's first state)")
    s.add_argument("--split", choices=SPLITS, help="how rows are held out: whole trajectories, random rows, or "
                   "none (default: by-trajectory for a trajectory file, random for a state file)")
    s.add_argument("--heldout", type=float, default=HELDOUT, help="fraction held out (of trajectories or rows)")
    s.add_argument("--window", type=int, default=WINDOW, help="Savitzky-Golay window (odd, samples) for the "
                   "derivatives of a trajectory file")
    s.add_argument("--polyorder", type=int, default=POLYORDER, help="Savitzky-Golay polynomial degree (>= 2)")
    s.add_argument("--out", default="results/fit", help="results folder")
    s.add_argument("--framework", default="jax", help="jax | torch")
    s.add_argument("--steps", type=int, default=2000, help="optimiser steps, >= 1")
    s.add_argument("--batch", type=int, default=256, help="batch size, >= 1; at most the training rows")
    s.add_argument("--hidden", default="128,128", help="comma-separated MLP widths")
    s.add_argument("--activation", default="softplus", help="softplus | relu | relu2 | relu3 | tanh | sigmoid")
    s.add_argument("--lr", type=float, default=1e-3, help="peak learning rate, > 0")
    s.add_argument("--schedule", default="onecycle", help="onecycle | constant")
    s.add_argument("--lr-final", type=float, default=1e-4, help="one-cycle: final rate as a fraction of --lr")
    s.add_argument("--weight-decay", type=float, default=0.0, help="L2 penalty: coefficient of sum(theta^2) added "
                   "to the loss")
    s.add_argument("--loss", default="l1", help="l1 | mse (per sample summed over components, mean over the batch)")
    s.add_argument("--seed", type=int, default=0, help="initialisation and batch-order seed, >= 0")
    s.add_argument("--delan-eps", type=float, default=0.01, help="DeLaN: epsilon of M = L L^T + eps I")
    s.add_argument("--delan-offset", type=float, default=2.0, help="DeLaN: diag(L) = softplus(raw + offset)")
    s.add_argument("--angle-wrap", action="store_true", help="input feature: wrap q to [-pi, pi) before the MLP")
    s.add_argument("--input-scale", default="none", help="input feature: multipliers of the MLP inputs [q, qdot"
                   "(, qddot)]: none, auto (1 / standard deviation over the training rows) or numbers such as "
                   "1,1,0.3,0.3")
    s.add_argument("--system", help="a system name (see `lagbench list`) whose true energy (and DeLaN terms) the "
                   "evaluation compares against (default: none)")
    s.add_argument("--energy", help="your energy function E(q, qdot) as module:function (importable from here; "
                   "(N, d) arrays to (N,)), compared along the rollouts in place of --system's")
    s.add_argument("--substeps", type=int, default=2, help="RK4 steps per sample interval in the rollouts")
    s.add_argument("--horizon", type=float, help=HORIZON_HELP + " (default: whole trajectories)")
    s.add_argument("--quiet", action="store_true", help="no progress bar")
    s.add_argument("--device", default="auto", choices=("auto", "cpu", "gpu"), help=DEVICE_HELP)
    s.set_defaults(func=cmd_fit)
    _show_defaults(s)

    s = sub.add_parser("evaluate", help="judge fitted models on a data file",
                       description="Evaluate fitted models on a data file: one-step errors per component, rollouts "
                       "from each trajectory's first state, energy drift (and the true energy error with --system), "
                       "DeLaN's decomposition. Writes OUT/units/evaluate/<framework>/<model>/seed<k>/ and OUT/data/.")
    s.add_argument("--model", required=True, help="a fit's unit folder, or a `lagbench fit` results folder (every "
                   "fitted model in it)")
    s.add_argument("--data", required=True, help=DATA_HELP)
    s.add_argument("--out", default="results/evaluate", help="results folder")
    s.add_argument("--framework", help="jax | torch (default: the one each model was trained in)")
    s.add_argument("--system", help="a system name for the true energy (default: the fit's --system)")
    s.add_argument("--energy", help="your energy function as module:function (default: the fit's)")
    s.add_argument("--substeps", type=int, help="RK4 steps per sample interval (default: the fit's)")
    s.add_argument("--horizon", type=float, help=HORIZON_HELP + " (default: the fit's)")
    s.add_argument("--quiet", action="store_true", help="no progress bar")
    s.add_argument("--device", default="auto", choices=("auto", "cpu", "gpu"), help=DEVICE_HELP)
    s.add_argument("--window", type=int, help="Savitzky-Golay window (default: the fit's)")
    s.add_argument("--polyorder", type=int, help="Savitzky-Golay degree (default: the fit's)")
    s.set_defaults(func=cmd_evaluate)
    _show_defaults(s)
