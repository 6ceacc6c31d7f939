"""The command line of bringing your own data: `lagbench simulate`, `fit` and `evaluate` (registered on
`lagbench.cli`'s parser by `add_commands`). Every option shows its default in `--help`; bad input is
one line naming the option (raised as ValueError, printed by `cli.main`)."""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from lagbench import options
from lagbench.options import renamed
from lagbench.options import show_defaults as _show_defaults
from lagbench.replication.claims.base import PROFILES
from lagbench.replication.evaluation.diverged import note as diverged_note
from lagbench.replication.fit import options as fit_options
from lagbench.replication.training.device import HELP as DEVICE_HELP

DATA_HELP = ("a trajectory file: .csv with columns traj, t, q0..q{d-1} and optional qdot0.., qddot0.., tau0.. "
             "(.npz: arrays traj, t, q, ...), derivatives it lacks estimated by a Savitzky-Golay filter; or a "
             "state file: columns (arrays) q, qdot, qddot and optional tau (format: docs/fit.md)")


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
    from lagbench.replication.fit import kind_defaults
    from lagbench.replication.fit.progress import TrainingBar
    from lagbench.replication.fit.task import fit, resolved
    from lagbench.replication.training import device

    device.apply(args.device, (args.framework,))   # before anything is written
    given = fit_options.from_args(args)
    o, task, recording, dof = resolved(args.data, given)   # a refused option: one line, nothing written
    if not args.quiet and set(kind_defaults.FROM_PROTOCOL) - set(given):
        print(f"lagbench fit: {args.model}'s defaults from {kind_defaults.source(args.model, task, recording, dof)} "
              f"where not given ({o.steps} steps, batch {o.batch}, hidden {','.join(map(str, o.hidden))}, lr {o.lr:g}"
              f"{f', {o.restarts} restarts' if o.restarts else ''}{', spike guard' if o.guard_clip or o.guard_skip else ''}"
              f"{f', early stop at patience {o.patience}' if o.patience else ''})", file=sys.stderr)
    # the training's bar (restarts and main training in one) is made at its first log row, so that a refused
    # option prints one line and nothing else; closed when the evaluation starts
    bar = TrainingBar(f"lagbench fit {args.model}", args.quiet)
    rollouts = RolloutBars(args.quiet, f"lagbench fit {args.model}")

    def on_progress(label, done, total):
        bar.close()
        rollouts(label, done, total)

    try:
        if args.tune:
            from lagbench.replication.fit.tune import tune_fit

            d, ledger = tune_fit(args.data, out=args.out, n_configs=args.tune, on_log=bar.row, on_progress=on_progress,
                                 on_train=bar.start, **fit_options.from_args(args))
            scores = ", ".join(f"{k}: {'-' if v is None else f'{v:.4g}'}" for k, v in ledger["scores"].items())
            print(f"tune: chose configuration {ledger['chosen']} of {len(ledger['configs'])} "
                  f"(--lr {ledger['options']['lr']:.4g} --hidden {','.join(map(str, ledger['options']['hidden']))}; "
                  f"held-out {scores}), ledger in {Path(args.out) / 'tune'}")
        else:
            d = fit(args.data, out=args.out, on_log=bar.row, on_progress=on_progress, on_train=bar.start,
                    **fit_options.from_args(args))
    finally:
        bar.close()
        rollouts.close()
    label = args.model + ("_dissipative" if args.dissipation else "")   # a dissipative fit's own folder
    folder = Path(args.out) / "units" / "fit" / args.framework / label / f"seed{args.seed}"
    if d["status"] != "ok":
        print(f"lagbench: fit failed: {d['failure']['message']} (record in {folder})", file=sys.stderr)
        return 1
    from lagbench.replication.fit.competence import competence, describe

    stop = d.get("early_stop") or {}
    if stop.get("stopped_at") is not None:
        at = stop["stopped_at"] + 1
        anneal = min(stop.get("anneal", 0), o.steps - at)
        print(f"lagbench fit: early stop at step {at} of {o.steps}, {stop['patience']} held-out evaluations in a row "
              f"without a new best by {stop['min_improvement']:g} of it (held-out loss best {stop['best_heldout_loss']:.4g} "
              f"at step {stop['best_step'] + 1}, then {stop['last_heldout_loss']:.4g})"
              + (f"; the rate then annealed over {anneal} more steps, {at + anneal} in all" if anneal else ""),
              file=sys.stderr)
    again = " (unchanged data and options: the earlier fit)" if d.get("reused") else ""
    value = d.get("final_train_loss") if d["metric"] == "final_train_loss" else d["metrics"].get(d["metric"])
    c = competence(d["metrics"], d["metric"])
    shown = "none (not finite)" if value is None else f"{value:.6g}"
    print(f"{'ok' if c is None or c['learned'] else 'done'}: {d['metric_label']} {shown}"
          f"{f' ({describe(c)})' if c else ''}{diverged_note(d['metrics'])}, written to {folder}{again}")
    return 1 if args.strict and c is not None and not c["learned"] else 0


def _fitted_folder(args) -> str:
    """--fitted, or its old spelling --model."""
    fitted = renamed("evaluate", args.fitted, args.fitted_old, None, "--fitted", "--model", "in `fit`, --model is the model kind")
    if fitted is None:
        raise ValueError("--fitted: required; give a fit's unit folder or a `lagbench fit` results folder")
    return fitted


def cmd_predict(args):
    """`evaluate --predict module:function --system NAME`: a predictor from outside scored on a system."""
    from lagbench.files.user_functions import import_function
    from lagbench.replication.predictor.score import score

    given = [o for o, v in (("--data", args.data), ("--fitted", args.fitted or args.fitted_old), ("--energy", args.energy),
                            ("--frameworks", args.framework), ("--time-unit", args.time_unit)) if v is not None]
    if given:
        raise ValueError(f"{given[0]}: not used with --predict (the predictor is scored on --system's own states)")
    if not args.system:
        raise ValueError("--system: required with --predict; see `lagbench list` for the systems")
    fn = import_function(args.predict, "--predict")
    bar = []   # made at the first call: a refused option or import prints one line and nothing else

    def on_call(done, total):
        from tqdm.auto import tqdm

        if not bar:
            bar.append(tqdm(total=total, desc=f"lagbench evaluate --predict {args.label or args.predict}", unit="call",
                            disable=args.quiet))
        bar[0].total = total
        bar[0].update(done - bar[0].n)

    try:
        d = score(fn, args.system, profile=args.profile, out=args.out, label=args.label, name=args.predict,
                  call_limit=args.call_limit, on_call=on_call)
    finally:
        for b in bar:
            b.close()
    m = d["metrics"]
    keys = ("heldout_l1", "null_heldout_l1", "rollout_gmean_err", "energy_err_final", "vpt_s", "chaos_floor_vpt_s",
            "lyapunov_time_s")
    print(f"{d['model']} on {args.system} (scored as {d['scored_like']['claim']}'s {d['scored_like']['model']}, "
          f"test split): " + ", ".join(f"{k} {m[k]:.4g}" if m[k] is not None else f"{k} -" for k in keys if k in m) + f"; written to {d['folder']}")
    if d["status"] != "ok":
        print(f"lagbench: --predict {args.predict}: failed: {d['failure']['message']} (record in {d['folder']})",
              file=sys.stderr)
        return 1


def cmd_evaluate(args):
    from lagbench.replication.fit.evaluate_file import evaluate

    if args.predict is not None:
        return cmd_predict(args)
    if args.call_limit is not None:
        raise ValueError("--call-limit: with --predict only (a fitted model is the suite's own code)")
    if args.data is None:
        raise ValueError("--data: required; give the trajectory file to evaluate on (or --predict to score a function)")
    fitted = _fitted_folder(args)
    rollouts = RolloutBars(args.quiet, "lagbench evaluate")
    try:
        done = evaluate(fitted, args.data, out=args.out, framework=args.framework, system=args.system,
                        substeps=args.substeps, window=args.window, polyorder=args.polyorder, energy=args.energy,
                        device=args.device, horizon=args.horizon, on_progress=rollouts, time_unit=args.time_unit)
    finally:
        rollouts.close()
    from lagbench.replication.fit.competence import competence, describe
    from lagbench.replication.fit.rows import Overlap

    for d in done:
        m, loss = d["metrics"], f"test_{d['protocol']['loss']}"
        c = competence(m, loss)
        again = " (the earlier evaluation)" if d.get("reused") else ""
        print(f"{d['model']} ({d['framework']}): {evaluation_line(m, 'test', loss)}"
              f"{f' ({loss}: {describe(c)})' if c else ''}; written to {d['folder']}{again}")
        shared = (d.get("eval_config") or {}).get("training_rows")
        if shared:
            print(f"lagbench evaluate: warning: --data {args.data}: {Overlap(**shared).words()} are training rows "
                  f"of the fit in {(d.get('eval_config') or {}).get('model')}; their errors are not predictions of "
                  f"unseen data", file=sys.stderr)


def evaluation_line(m: dict, where: str, loss: str) -> str:
    """The metrics of an evaluation set `where` as the console shows them: an energy error beyond the data's
    own scale as "diverged" (`evaluation.diverged`), never as a number, and the rollouts that diverged counted."""
    from lagbench.replication.evaluation.diverged import rollouts_words, shown

    keys = (loss, f"{where}_rollout_gmean_err", f"{where}_learned_energy_drift", f"{where}_energy_err_final")
    parts = [f"{k} {m[k]:.4g}" if k in keys[:2] else f"{k} {shown(m[k])}" for k in keys if m.get(k) is not None]
    blown = rollouts_words(m, where)
    return ", ".join(parts) + (f" (DIVERGED: {blown})" if blown else "")


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

    s = sub.add_parser("fit", help="train a model on your own data (format: docs/fit.md)",
                       description="Train one model on a data file and write OUT/units/fit/<framework>/<model>/"
                       "seed<k>/ (result.json, train_log.csv, checkpoint.npz, one_step.csv, rollouts.csv), and the "
                       "prepared rows to OUT/data/. Optimiser: Adam; learning rate: the one-cycle cosine of the "
                       "original LNN code (starts at 35 % of --lr, peaks at --lr 37.5 % into training, ends at "
                       "--lr x --lr-final) or constant. A fit of other data or options already there is kept as "
                       "superseded-<time>-seed<k>. Load the model in Python with "
                       "lagbench.replication.fit.load.load_fitted(folder).")
    s.add_argument("--data", required=True, help=DATA_HELP)
    s.add_argument("--out", default="results/fit", help="results folder")
    fit_options.add_arguments(s)
    options.respell(s, "--framework", "--frameworks", help="the one framework the model trains in: jax or torch")
    options.check(s, "framework", options.one_framework("fit"))
    s.add_argument("--quiet", action="store_true", help="no progress bar")
    s.add_argument("--strict", action="store_true", help="exit with status 1 when the model is not clearly better "
                   "than the null predictor (at most half its error on the reported set)")
    s.add_argument("--device", default="auto", choices=("auto", "cpu", "gpu"), help=DEVICE_HELP)
    s.add_argument("--tune", type=int, default=0, metavar="N",
                   help="choose --lr and --hidden by the suite's declared search first: N configurations (the given "
                   "options, then peak rate x 1/3, 1, 3 and widths x 1/2, 1, 2), each fitted to the training rows and "
                   "scored on the held-out rows (never the test file); the best is fitted again into OUT "
                   "(ledger in OUT/tune/) (default: 0, no search)")
    s.set_defaults(func=cmd_fit)
    _show_defaults(s)

    s = sub.add_parser("evaluate", help="judge fitted models on a data file, or score your own predictor",
                       description="Evaluate fitted models on a data file: one-step errors per component, rollouts "
                       "from each trajectory's first state, energy drift (and the true energy error with --system), "
                       "DeLaN's decomposition. Writes OUT/units/evaluate/<framework>/<model>/seed<k>/ and OUT/data/. "
                       "With --predict module:function --system NAME: your function (NumPy q, qdot of shape (N, d) "
                       "-> qddot (N, d), from any framework) scored as the suite scores its own models on that "
                       "system (test split): one-step error beside the null predictor's, RK4 rollouts, energy "
                       "error, valid prediction time against the chaos floor; writes OUT/predict/<system>/<label>/.")
    s.add_argument("--fitted", help="required: a fit's unit folder, or a `lagbench fit` results folder (every "
                   "fitted model in it)")
    # `--model` names a model kind in `fit`; here it is the old spelling of --fitted, still read
    s.add_argument("--model", dest="fitted_old", help=argparse.SUPPRESS)
    s.add_argument("--data", help="required without --predict: " + DATA_HELP)
    s.add_argument("--predict", metavar="MODULE:FUNCTION", help="score your function qddot = f(q, qdot) on --system "
                   "(module importable from the working folder, or path/to/file.py:function)")
    s.add_argument("--profile", default="quick", choices=PROFILES,
                   help="with --predict: whose held-out set and rollouts to score on")
    s.add_argument("--label", help="with --predict: the name of its results folder (default: the function's name)")
    s.add_argument("--call-limit", type=float, metavar="SECONDS", help="with --predict: the most seconds one call of "
                   "the function may take; a call past it stops the scoring with one line (the progress bar's "
                   "estimate, from the first calls, shows the whole) (default: no limit)")
    s.add_argument("--out", default="results/evaluate", help="results folder")
    options.add(s, "--frameworks", "--framework", dest="framework", help="the one framework to evaluate in: jax or "
                "torch (default: the one each model was trained in)")
    options.check(s, "framework", options.one_framework("evaluate"))
    s.add_argument("--system", help="a system name for the true energy (default: the fit's --system); with "
                   "--predict, the system to score on")
    s.add_argument("--energy", help="your energy function as module:function (default: the fit's)")
    s.add_argument("--substeps", type=int, help="RK4 steps per sample interval (default: the fit's)")
    s.add_argument("--horizon", type=float, help=fit_options.HORIZON_HELP + " (default: the fit's)")
    s.add_argument("--quiet", action="store_true", help="no progress bar")
    s.add_argument("--device", default="auto", choices=("auto", "cpu", "gpu"), help="where the fitted models "
                   "predict and roll out (not used with --predict): auto (a GPU where the framework sees one, else "
                   "the CPU), cpu, or gpu (an error if the framework sees none) (default: auto)")
    s.add_argument("--window", type=int, help="Savitzky-Golay window (default: the fit's)")
    s.add_argument("--polyorder", type=int, help="Savitzky-Golay degree (default: the fit's)")
    s.add_argument("--time-unit", choices=tuple(fit_options.TIME_UNITS), help="the unit of --data's t column: s or "
                   "ms (default: the fit's)")
    s.set_defaults(func=cmd_evaluate)
    _show_defaults(s)
