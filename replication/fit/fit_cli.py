"""`lagbench fit`: train one model on a user's data file. `add_fit(sub)` registers the command and its options
(`replication.fit.options`); `cmd_fit` runs it with a training bar and rollout bars, prints the defaults taken,
the periodic inputs and dissipation chosen (`--periodic`, `--dissipation`; before the training), an early stop,
the derivative window chosen from the data (`--window auto`) and the verdict line, and returns 1 where the fit
failed (or, with --strict, learned nothing). `DATA_HELP` describes a data file, for `evaluate` as well."""
from __future__ import annotations

import sys
from pathlib import Path

from lagbench import options
from lagbench.options import show_defaults as _show_defaults
from lagbench.replication.evaluation.diverged import note as diverged_note
from lagbench.replication.fit import options as fit_options
from lagbench.replication.fit.rollout_bars import RolloutBars
from lagbench.replication.training.device import HELP as DEVICE_HELP

DATA_HELP = ("a trajectory file: .csv with columns traj, t, q0..q{d-1} and optional qdot0.., qddot0.., tau0.. "
             "(.npz: arrays traj, t, q, ...), derivatives it lacks estimated by a Savitzky-Golay filter; or a "
             "state file: columns (arrays) q, qdot, qddot and optional tau (format: docs/fit.md)")


def cmd_fit(args):
    from lagbench.replication.fit import kind_defaults
    from lagbench.replication.fit.progress import TrainingBar
    from lagbench.replication.fit.resolve import resolved
    from lagbench.replication.fit.task import fit
    from lagbench.replication.training import device

    device.apply(args.device, (args.framework,))   # before anything is written
    given = fit_options.from_args(args)
    o, task, recording, dof, _, noise, _ = resolved(args.data, given)   # a refused option: one line, nothing written
    if not args.quiet and set(kind_defaults.FROM_PROTOCOL) - set(given):
        print(f"lagbench fit: {args.model}'s defaults from "
              f"{kind_defaults.source(args.model, task, recording, dof, given, noise)} "
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
            choices_line(d.get("eval_config") or {})
            scores = ", ".join(f"{k}: {'-' if v is None else f'{v:.4g}'}" for k, v in ledger["scores"].items())
            print(f"tune: chose configuration {ledger['chosen']} of {len(ledger['configs'])} "
                  f"(--lr {ledger['options']['lr']:.4g} --hidden {','.join(map(str, ledger['options']['hidden']))}; "
                  f"held-out {scores}), ledger in {Path(args.out) / 'tune'}")
        else:
            d = fit(args.data, out=args.out, on_log=bar.row, on_progress=on_progress, on_train=bar.start,
                    on_choices=choices_line, **fit_options.from_args(args))
    finally:
        bar.close()
        rollouts.close()
    # a dissipative fit's own folder (lnn_dissipative), where --dissipation chose that form
    folder = Path(args.out) / "units" / "fit" / args.framework / d.get("model", args.model) / f"seed{args.seed}"
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
    from lagbench.replication.fit import derivative_window

    cfg = d.get("eval_config") or {}
    for what, key in (("derivatives", "derivatives"), ("test file's derivatives", "test_derivatives")):
        if (cfg.get(key) or {}).get("rule") == derivative_window.AUTO:   # the window chosen from the data, and why
            print(f"lagbench fit: {what}: {derivative_window.describe(cfg[key])}", file=sys.stderr)
    again = " (unchanged data and options: the earlier fit)" if d.get("reused") else ""
    value = d.get("final_train_loss") if d["metric"] == "final_train_loss" else d["metrics"].get(d["metric"])
    c = competence(d["metrics"], d["metric"])
    shown = "none (not finite)" if value is None else f"{value:.6g}"
    print(f"{'ok' if c is None or c['learned'] else 'done'}: {d['metric_label']} {shown}"
          f"{f' ({describe(c)})' if c else ''}{diverged_note(d['metrics'])}, written to {folder}{again}")
    return 1 if args.strict and c is not None and not c["learned"] else 0


def choices_line(records: dict) -> None:
    """The periodic inputs, the dissipation, for an LNN the even Lagrangian, and a loss other than the
    acceleration loss that `--loss-target auto` chose (`--periodic`, `--dissipation`, `--even-velocity`,
    `--loss-target`), and why: one line each, printed as the derivative window is, also under --quiet."""
    from lagbench.replication.fit import energy_trend, even_velocity, loss_target, periodic_coords

    if records.get("periodic"):
        print(f"lagbench fit: periodic inputs: {periodic_coords.describe(records['periodic'])}", file=sys.stderr)
    if records.get("dissipation"):
        print(f"lagbench fit: dissipation: {energy_trend.describe(records['dissipation'])}", file=sys.stderr)
    if records.get("even_velocity"):
        print(f"lagbench fit: Lagrangian even in q-dot: {even_velocity.describe(records['even_velocity'])}",
              file=sys.stderr)
    if loss_target.auto_departed(records.get("loss_target") or {}):
        print(f"lagbench fit: loss: {loss_target.describe(records['loss_target'])}", file=sys.stderr)


def add_fit(sub) -> None:
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
