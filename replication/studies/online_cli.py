"""`lagbench online`: its command line (the study is `online.py`, the learners `online_learner.py`).

Every option is checked before any work (a one-line error naming it); the command writes only into
OUT/online/ (the two-link arm, the default `--system`) or OUT/online_<system>/ (another arm). JAX and
PyTorch are held to one thread (`online.one_thread`) before either starts computing."""
from __future__ import annotations

from pathlib import Path

from lagbench import options

MAX_SECONDS = 3600.0


def _choices(option: str, text: str, valid) -> tuple[str, ...]:
    got = tuple(dict.fromkeys(t.strip() for t in text.split(",") if t.strip()))
    if not got or any(t not in valid for t in got):
        raise ValueError(f"{option} {text}: expected a comma-separated subset of {', '.join(valid)}")
    return got


def _number(option: str, value: float, low: float, high: float = float("inf"), strict: bool = True) -> float:
    ok = (low < value if strict else low <= value) and value <= high
    if not ok:
        bound = f"above {low:g}" if strict else f">= {low:g}"
        raise ValueError(f"{option} {value:g}: expected a number {bound}" + (f" and at most {high:g}" if high < 1e300 else ""))
    return value


def _check(args) -> dict:
    from lagbench.replication.studies import control as C
    from lagbench.replication.studies.online_learner import KINDS
    from lagbench.systems.arm_data import ARMS

    if args.system not in ARMS:
        raise ValueError(f"--system {args.system}: expected one of {', '.join(ARMS)}")
    tick = 1.0 / C.RATE
    # the system is passed (and recorded in setup.json) only where it is not the default two-link arm
    other = {} if args.system == C.SYSTEM else {"system": args.system}
    return {**other, "seconds": _number("--seconds", args.seconds, tick, MAX_SECONDS, strict=False),
            "every": int(_number("--every", args.every, 1, strict=False)),
            "steps": int(_number("--steps", args.steps, 0, strict=False)),
            "batch": int(_number("--batch", args.batch, 1, strict=False)),
            "buffer": int(_number("--buffer", args.buffer, 1, strict=False)),
            "window": _number("--window", args.window, tick, MAX_SECONDS, strict=False),
            "threshold": _number("--threshold", args.threshold, 0.0),
            "sustain": _number("--sustain", args.sustain, 0.0, MAX_SECONDS, strict=False),
            "n_unseen": int(_number("--unseen-refs", args.unseen_refs, 0, strict=False)),
            "seeds": options.seeds(args.seeds),
            "frameworks": options.frameworks(args.frameworks),
            "models": _choices("--models", args.models, KINDS)}


def cmd_online(args):
    import math

    from tqdm.auto import tqdm

    from lagbench.files.results import output_folder
    from lagbench.replication.studies import online as O

    kw = _check(args)
    folder = output_folder(Path(args.out) / ("online" if "system" not in kw else f"online_{kw['system']}"), "--out")
    threads = O.one_thread()
    ticks = int(round(kw["seconds"] * O.C.RATE))
    n_ctrl = 2 + len(kw["models"]) * len(kw["frameworks"]) * len(kw["seeds"])
    bar = tqdm(total=n_ctrl * ticks, desc="lagbench online", unit="tick", unit_scale=True, disable=args.quiet)
    try:
        _, summary = O.write_study(folder, settings={"threads": threads}, progress=bar.update, **kw)
    finally:
        bar.close()
    cols = ["controller", "framework", "seed", *O.TIMES, "final_ratio_to_pd", "unseen_ratio_to_pd",
            "inference_us_mean", "learning_us_mean", "compute_us_p99", "fits_period_mean", "fits_period_p99"]
    table = summary[cols].astype(object)
    for c in O.TIMES:
        table[c] = ["never" if math.isnan(x) else f"{x:g}" for x in summary[c]]
    print(table.to_string(index=False, float_format=lambda x: f"{x:.3g}", na_rep="-"))
    print(f"the bar: a window's tracking MSE at most {kw['threshold']:g} x PD alone's. t_reach_s: the end of the "
          f"first window of the first run of windows at the bar lasting {kw['sustain']:g} s; t_first_cross_s: of the "
          f"first window at it; t_settle_s: of the first from which every later window is. Written to {folder}")


def add_command(sub) -> None:
    from lagbench.replication.studies import online as O

    s = sub.add_parser("online", help="DeLaN and the feed-forward net learning online while they track the two-link "
                                      "arm (writes OUT/online/) or the four-joint arm (OUT/online_four_joint_arm/)",
                       description="Computed-torque control at 500 Hz of the SymPy two-link arm (as `lagbench "
                       "control`) whose inverse model starts untrained and learns from its own control loop: each "
                       "tick's (q, qdot, measured qddot, applied torque) enters a replay buffer, and every --every "
                       "ticks the model takes --steps Adam steps (claim 9's loss and learning rate) on a minibatch "
                       "of it. References: the training family back to back for --seconds; the final model is then "
                       "scored frozen on the unseen family. PD alone and the true inverse dynamics are the floors. "
                       "Writes OUT/online/curves.csv (per window: tracking MSE, microseconds of inference and of "
                       "learning per tick), summary.csv (time to reach the threshold and hold it --sustain seconds, "
                       "time to first cross it, final and unseen MSE, compute "
                       "per tick against the 2 ms period) and setup.json. With --system four_joint_arm the same on "
                       "the SymPy four-joint arm, into OUT/online_four_joint_arm/. See docs/online_control.md.")
    s.add_argument("--out", default="results/quick", help="results folder; writes OUT/online/ (OUT/online_<system>/ "
                   "for another arm than the two-link arm) (default: results/quick, which `lagbench report` reads "
                   "unless given --results)")
    s.add_argument("--system", default="two_link_arm", help="the arm: two_link_arm or four_joint_arm, whose "
                   "learners have 4 joints (default: two_link_arm)")
    s.add_argument("--seconds", type=float, default=20.0, help="simulated seconds of learning while tracking "
                   "(default: 20)")
    s.add_argument("--every", type=int, default=O.EVERY, help=f"learn every K control ticks (default: {O.EVERY})")
    s.add_argument("--steps", type=int, default=O.STEPS, help=f"optimiser steps each time it learns; 0: no "
                   f"learning (default: {O.STEPS})")
    s.add_argument("--batch", type=int, default=O.BATCH, help=f"minibatch drawn from the buffer (default: {O.BATCH})")
    s.add_argument("--buffer", type=int, default=O.BUFFER, help=f"replay buffer: the last N samples (default: "
                   f"{O.BUFFER}, 10 s)")
    s.add_argument("--window", type=float, default=O.WINDOW, help=f"seconds of simulated time per curve point "
                   f"(default: {O.WINDOW:g})")
    s.add_argument("--threshold", type=float, default=O.THRESHOLD, help=f"the tracking-MSE bar as a fraction of PD "
                   f"alone's in the same window (default: {O.THRESHOLD:g})")
    s.add_argument("--sustain", type=float, default=O.SUSTAIN, help=f"seconds the windows must stay at the bar for "
                   f"t_reach_s; 0: the first window at it (default: {O.SUSTAIN:g})")
    s.add_argument("--seeds", nargs="+", default=["0"], help="model seeds, comma- or space-separated (default: 0)")
    s.add_argument("--frameworks", default="jax", help="comma-separated: jax, torch (default: jax, as `lagbench "
                   "run`'s quick profile)")
    s.add_argument("--models", default="delan,ff", help="comma-separated: delan, ff (default: delan,ff)")
    s.add_argument("--unseen-refs", type=int, default=O.N_UNSEEN, help=f"unseen-family references the final model "
                   f"tracks, 4 s each; 0: none (default: {O.N_UNSEEN})")
    s.add_argument("--quiet", action="store_true", help="no progress bar")
    s.set_defaults(func=cmd_online)
