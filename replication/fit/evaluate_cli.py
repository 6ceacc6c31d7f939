"""`lagbench evaluate`: fitted models judged on a data file (`cmd_evaluate`, one line per model by
`evaluation_line`), or with --predict a user's function scored on a system (`cmd_predict`). `add_evaluate(sub)`
registers the command and its options; an option that does not go with the others is one line naming it."""
from __future__ import annotations

import argparse
import sys

from lagbench import options
from lagbench.options import renamed
from lagbench.options import show_defaults as _show_defaults
from lagbench.replication.claims.base import PROFILES
from lagbench.replication.fit import options as fit_options
from lagbench.replication.fit.fit_cli import DATA_HELP
from lagbench.replication.fit.rollout_bars import RolloutBars
from lagbench.replication.fit.trajectories import window_value


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


def add_evaluate(sub) -> None:
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
    s.add_argument("--window", type=window_value, help="Savitzky-Golay window: auto (chosen from this file's noise "
                   "and motion) or an odd number of samples (default: the fit's)")
    s.add_argument("--polyorder", type=int, help="Savitzky-Golay degree (default: the fit's)")
    s.add_argument("--time-unit", choices=tuple(fit_options.TIME_UNITS), help="the unit of --data's t column: s or "
                   "ms (default: the fit's)")
    s.set_defaults(func=cmd_evaluate)
    _show_defaults(s)
