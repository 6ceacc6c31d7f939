"""Learning online while tracking: computed-torque control of the two-link arm whose inverse model starts untrained
and learns from the samples its own control loop produces (DeLaN's "learns online in real time"). Every
function takes `system`, the arm (`systems.arm_data.ARMS`; default `control.SYSTEM`, the two-link arm): its
SymPy plant, its references, gains `control.gains(dof)` and learners of its `dof`.

The loop is `control.py`'s: tau = tau_hat(q_d, qdot_d, qddot_d) + KP (q_d - q) + KD (qdot_d - qdot) at `RATE`
(500) Hz, the torque held over each 2 ms period, the SymPy plant integrated by RK4 (`control.period`, 4 steps a
period, float64). One arm tracks the references of `refs` back to back, each from its own initial state (the
arm is placed there when it starts). At every tick the executed sample (q, qdot, the plant's acceleration
under the applied torque, that torque) goes into a `ReplayBuffer` of the last `buffer` samples, and every
`every` ticks the learner takes `steps` optimiser steps (the suite's `Stepper`) on minibatches of `batch`
drawn from it (compiled before the first tick); the next tick's feed-forward uses the updated model
(`online_learner`).

`run_online(ctrl, refs, every, steps, batch, buffer, window, seed) -> (windows, ticks)`: one controller over the
whole sequence. `ctrl` is a learner (`online_learner.learner`), "exact" (the true inverse dynamics), or None
(PD alone). windows: a list of dicts, one per `window` seconds of simulated time: t_start (s), track_mse (mean
over its ticks of |q - q_d|^2, rad^2, summed over joints; ticks of a diverged reference left out),
n_diverged (such ticks), inference_us_per_tick and learning_us_per_tick (mean wall-clock microseconds per
tick of the feed-forward call and of the buffer write plus optimiser steps, time.perf_counter), steps (the
optimiser steps taken so far). ticks: {"inference_us", "learning_us"}, each (T,) over the ticks that ran (a
diverged reference's rest is skipped), and "diverged_refs" (the references that diverged).

`online_study(models, frameworks, seeds, seconds, ...) -> (curves, summary)`: PD alone and the true inverse
dynamics (no learning, framework "numpy", seed "-"), then each model x framework x seed learning on `seconds`
of the training family (`control.references("train", ...)`, generator seed `control.SEED`). A window's
ratio_to_pd is its MSE over PD alone's in the same window (the same references at the same times). Summary,
one row per controller, framework and seed: `threshold` (the stated bar: a window MSE at most `threshold` x
PD alone's), `sustain` (seconds the bar must hold), t_reach_s (the sustained crossing: end of the first window
of the first run of consecutive windows at the bar lasting `sustain` seconds, `sustain_start`; NaN: never),
t_first_cross_s (end of the first window at the bar, however briefly; NaN: never), t_settle_s (end of the
window from which every later window is at the bar), first/final window MSE and ratio, unseen_mse and its
ratio to PD (the frozen final model tracking `n_unseen` references of the unseen family, `control.track`),
compute per tick (mean, median and p99 of inference + learning, microseconds) and whether it fits the control
period (mean, p99). The pieces claim 13 shares (`replication.evaluation.online_claim`): `ratio_to_pd(windows,
pd_windows)` (each window's MSE over PD alone's in the window that starts at the same time), `summary_row(w,
ticks, threshold, window, sustain)` (a controller's summary columns from its windows with their ratios; NaN:
never), `at_bar`, `sustain_windows`, `sustain_start` (the sustained crossing's pieces) and `unseen(ctrl,
n_unseen, duration, seed)` (the frozen controller on the unseen family's references of generator seed
`seed`). `write_study(folder, ...)` writes FOLDER/curves.csv, summary.csv and setup.json (the settings, the
threshold's definition and the threads the timings ran on: `one_thread()`).
"""
from __future__ import annotations

import math
import time

import numpy as np
import pandas as pd

from lagbench.replication.studies import control as C

WINDOW = 0.5        # seconds of simulated time per curve point
EVERY, STEPS, BATCH, BUFFER = 1, 1, 64, 5000   # learn at every tick, one step of 64; 10 s of samples
THRESHOLD = 0.1     # the bar: window MSE <= THRESHOLD x PD alone's in the same window
SUSTAIN = 5.0       # seconds the bar must hold to count as reached: 10 windows, longer than one reference (4 s)
N_UNSEEN = 8
PERIOD_US = 1e6 / C.RATE
KEY = ["controller", "framework", "seed"]
TIMES = ("t_reach_s", "t_first_cross_s", "t_settle_s")   # the summary's times to the bar (NaN: never)
CURVE_COLUMNS = [*KEY, "t_start", "track_mse", "ratio_to_pd", "n_diverged", "inference_us_per_tick",
                 "learning_us_per_tick", "steps"]
SUMMARY_COLUMNS = [*KEY, "threshold", "sustain", "t_reach_s", "t_first_cross_s", "t_settle_s", "first_window_mse",
                   "final_window_mse", "final_ratio_to_pd", "n_diverged_ticks", "steps", "unseen_mse",
                   "unseen_ratio_to_pd", "unseen_diverged", "inference_us_mean", "learning_us_mean", "compute_us_mean",
                   "compute_us_median", "compute_us_p99", "fits_period_mean", "fits_period_p99"]


def sequence(family: str, seconds: float, rate: float = C.RATE, seed: int = C.SEED, system: str = C.SYSTEM) -> dict:
    """References of `family` covering `seconds`: ceil(seconds / d) of d = min(control.DURATION, seconds)
    seconds each (`control.references`), played in order."""
    d = min(C.DURATION, seconds)
    return C.references(family, n=math.ceil(seconds / d - 1e-9), duration=d, rate=rate, seed=seed, system=system)


def run_online(ctrl, refs: dict, every: int = EVERY, steps: int = STEPS, batch: int = BATCH, buffer: int = BUFFER,
               window: float = WINDOW, seed: int = 0, seconds: float | None = None, rate: float = C.RATE,
               substeps: int = C.SUBSTEPS, kp=None, kd=None, progress=None, system: str = C.SYSTEM):
    from lagbench import systems
    from lagbench.replication.studies.online_learner import ReplayBuffer

    plant = systems.get(system)
    qd, vd, ad = refs["q"], refs["qdot"], refs["qddot"]
    n_refs, n_t, dof = qd.shape
    kp = C.gains(dof)[0] if kp is None else kp
    kd = C.gains(dof)[1] if kd is None else kd
    total = (n_t - 1) * n_refs if seconds is None else min((n_t - 1) * n_refs, int(round(seconds * rate)))
    per_window = max(1, int(round(window * rate)))
    learns = ctrl is not None and ctrl != "exact" and steps > 0
    buf = ReplayBuffer(buffer, dof, seed)
    if learns:
        ctrl.warm(batch)   # compiled before the first tick, not inside it
    err, t_inf, t_learn = np.full(total, np.nan), np.zeros(total), np.zeros(total)
    h = 1.0 / rate / substeps
    step = C.period(plant, h, substeps, total)
    windows, done, tick, n_bad = [], 0, 0, 0
    for r in range(n_refs):
        q, v, bad = qd[r, :1].copy(), vd[r, :1].copy(), False   # (1, dof): the plant's batch of one
        for i in range(n_t - 1):
            if tick == total:
                break
            if not bad:
                err[tick] = np.sum((q[0] - qd[r, i]) ** 2)
                t0 = time.perf_counter()
                if ctrl is None:
                    ff = np.zeros(dof)
                elif ctrl == "exact":
                    ff = plant.inverse_dynamics(qd[r, i:i + 1], vd[r, i:i + 1], ad[r, i:i + 1])[0]
                else:
                    ff = ctrl.tau(qd[r, i], vd[r, i], ad[r, i])
                t1 = time.perf_counter()
                tau = ff + kp * (qd[r, i] - q) + kd * (vd[r, i] - v)
                with np.errstate(over="ignore", invalid="ignore"):   # a diverging state is caught below
                    q_next, v_next, a = step(q, v, tau)
                bad = bool(C.diverged(q_next, v_next)[0])
                t2 = time.perf_counter()
                if learns and not bad:
                    buf.add(q[0], v[0], a[0], tau[0])
                    if (tick + 1) % every == 0:
                        ctrl.learn(buf.sample(batch), steps)
                        done += steps
                t_inf[tick], t_learn[tick] = t1 - t0, time.perf_counter() - t2
                q, v = q_next, v_next
            tick += 1
            if tick % per_window == 0 or tick == total:
                start = (tick - 1) // per_window * per_window
                w = slice(start, tick)
                ok = np.isfinite(err[w])
                windows.append({"t_start": start / rate, "track_mse": float(err[w][ok].mean()) if ok.any() else math.nan,
                                "n_diverged": int((~ok).sum()), "inference_us_per_tick": 1e6 * float(t_inf[w].mean()),
                                "learning_us_per_tick": 1e6 * float(t_learn[w].mean()), "steps": done})
                if progress:
                    progress(tick - start)
        n_bad += bad
    ran = np.isfinite(err)
    return windows, {"inference_us": 1e6 * t_inf[ran], "learning_us": 1e6 * t_learn[ran], "diverged_refs": n_bad}


def unseen(ctrl, n_unseen: int, duration: float, seed: int = C.SEED, system: str = C.SYSTEM) -> dict:
    from lagbench import systems

    refs = C.references("test", n=n_unseen, duration=duration, seed=seed, system=system)
    if ctrl is None or isinstance(ctrl, str):
        inverse = None if ctrl is None else systems.get(system).inverse_dynamics
    else:
        inverse = ctrl.inverse
    s = C.scores(C.track(inverse, refs, system=system), refs)
    return {"unseen_mse": s.get("track_mse", math.nan), "unseen_diverged": s["n_diverged"]}


def ratio_to_pd(windows: pd.DataFrame, pd_windows: pd.DataFrame) -> pd.Series:
    """Each window's track_mse over PD alone's in the window that starts at the same t_start."""
    return windows["track_mse"] / windows["t_start"].map(pd_windows.set_index("t_start")["track_mse"])


def at_bar(ratio, threshold: float) -> np.ndarray:
    """(W,) bool: each window's ratio to PD alone at most `threshold`; NaN (no tick ran) and +inf (diverged)
    are above it."""
    r = np.asarray(ratio, dtype=np.float64)
    return np.isfinite(r) & (np.nan_to_num(r, nan=np.inf) <= threshold)


def sustain_windows(sustain: float, window: float) -> int:
    """The number of consecutive windows that make `sustain` seconds: ceil(sustain / window), at least 1."""
    return max(1, math.ceil(sustain / window - 1e-9))


def sustain_start(at: np.ndarray, n: int) -> int | None:
    """The index of the first window of the first run of at least `n` consecutive True windows of `at` (W,);
    None when no run lasts `n` windows (a run the end of the windows cuts short does not count)."""
    run = 0
    for i, ok in enumerate(np.asarray(at, dtype=bool)):
        run = run + 1 if ok else 0
        if run == n:
            return i - n + 1
    return None


def summary_row(w: pd.DataFrame, ticks: dict, threshold: float, window: float, sustain: float = SUSTAIN) -> dict:
    """A controller's summary columns (module docstring) from its windows `w` with their `ratio_to_pd`. The
    windows are `window` seconds each (a shorter last window counts as one)."""
    at = at_bar(w["ratio_to_pd"], threshold)
    ends = w["t_start"].to_numpy() + window
    first, reach = sustain_start(at, 1), sustain_start(at, sustain_windows(sustain, window))
    above = np.flatnonzero(~at)
    settle = 0 if not len(above) else above[-1] + 1   # the first window of the last run at the bar
    inf, learn = ticks["inference_us"], ticks["learning_us"]
    compute = inf + learn
    p99 = float(np.percentile(compute, 99)) if len(compute) else math.nan
    return {"threshold": threshold, "sustain": sustain,
            "t_reach_s": math.nan if reach is None else float(ends[reach]),
            "t_first_cross_s": math.nan if first is None else float(ends[first]),
            "t_settle_s": float(ends[settle]) if settle < len(at) else math.nan,
            "first_window_mse": float(w["track_mse"].iloc[0]), "final_window_mse": float(w["track_mse"].iloc[-1]),
            "final_ratio_to_pd": float(w["ratio_to_pd"].iloc[-1]), "n_diverged_ticks": int(w["n_diverged"].sum()),
            "steps": int(w["steps"].iloc[-1]), "inference_us_mean": float(np.mean(inf)),
            "learning_us_mean": float(np.mean(learn)), "compute_us_mean": float(np.mean(compute)),
            "compute_us_median": float(np.median(compute)), "compute_us_p99": p99,
            "fits_period_mean": bool(np.mean(compute) < PERIOD_US), "fits_period_p99": bool(p99 < PERIOD_US)}


def online_study(models=("delan", "ff"), frameworks=("jax", "torch"), seeds=(0,), seconds: float = 20.0,
                 every: int = EVERY, steps: int = STEPS, batch: int = BATCH, buffer: int = BUFFER,
                 window: float = WINDOW, threshold: float = THRESHOLD, sustain: float = SUSTAIN, hidden=None,
                 lr: float | None = None, refs: dict | None = None, n_unseen: int = N_UNSEEN,
                 unseen_duration: float = C.DURATION, progress=None, system: str = C.SYSTEM) -> tuple[pd.DataFrame, pd.DataFrame]:
    """See the module docstring. `refs`: the references to learn on (default `sequence("train", seconds)`);
    `hidden`, `lr`: the models' widths and learning rate (default claim 9's); n_unseen 0: no unseen score."""
    from lagbench import systems
    from lagbench.replication.run.environment import torch_threads
    from lagbench.replication.studies import online_learner as OL

    refs = sequence("train", seconds, system=system) if refs is None else refs
    dof = systems.get(system).dof
    plan = [("pd", "numpy", "-"), ("exact", "numpy", "-")]
    plan += [(m, fw, s) for m in models for fw in frameworks for s in seeds]
    curves, rows = [], []
    with torch_threads(1 if "torch" in frameworks else None):
        for name, fw, s in plan:
            ctrl = {"pd": None, "exact": "exact"}.get(name) if fw == "numpy" else \
                OL.learner(name, fw, int(s), hidden or OL.HIDDEN, lr, dof=dof)
            windows, ticks = run_online(ctrl, refs, every, steps, batch, buffer, window, seed=0 if s == "-" else int(s),
                                        seconds=seconds, progress=progress, system=system)
            key = {"controller": name, "framework": fw, "seed": s}
            curves += [{**key, **w} for w in windows]
            rows.append((key, ticks, unseen(ctrl, n_unseen, unseen_duration, system=system) if n_unseen else {}))
    df = pd.DataFrame(curves)
    df["ratio_to_pd"] = ratio_to_pd(df, df[df["controller"] == "pd"])
    pd_unseen = rows[0][2].get("unseen_mse", math.nan)
    summary = []
    for key, ticks, scores in rows:
        w = df[(df["controller"] == key["controller"]) & (df["framework"] == key["framework"])
               & (df["seed"] == key["seed"])]
        scores = scores or {"unseen_mse": math.nan, "unseen_diverged": math.nan}
        summary.append({**key, **summary_row(w, ticks, threshold, window, sustain), **scores,
                        "unseen_ratio_to_pd": scores["unseen_mse"] / pd_unseen})
    return df[CURVE_COLUMNS], pd.DataFrame(summary)[SUMMARY_COLUMNS]


def one_thread() -> dict:
    """Hold this process's compute to one thread where it still can, and say what is in force: XLA on one
    thread (`environment.one_thread_jax`: its backend started on one CPU, with `ONE_CORE_XLA` in XLA_FLAGS)
    and JAX's CPU programs run inline (`use_sync_dispatch`), both only before that start; PyTorch is set to
    one thread by `online_study` itself."""
    import os

    from lagbench.models.jax.compiled import async_dispatch, use_sync_dispatch
    from lagbench.replication.run.environment import one_thread_jax

    use_sync_dispatch()   # before `one_thread_jax` starts the backend
    one_thread_jax()
    return {"xla_flags": os.environ.get("XLA_FLAGS", ""), "jax_dispatch": "async" if async_dispatch() else "sync",
            "torch_threads": 1}


def write_study(folder, settings: dict | None = None, **kw) -> tuple[pd.DataFrame, pd.DataFrame]:
    from pathlib import Path

    from lagbench import systems
    from lagbench.files import results as R
    from lagbench.replication.run import environment

    folder = Path(folder)
    curves, summary = online_study(**kw)
    kp, kd = C.gains(systems.get(kw.get("system", C.SYSTEM)).dof)
    R.write_csv(folder / "curves.csv", curves)
    R.write_csv(folder / "summary.csv", summary)
    R.write_json(folder / "setup.json", {
        **(settings or {}), "sustain": SUSTAIN, **{k: v for k, v in kw.items() if k not in ("refs", "progress")},
        "threshold_definition": "a window's tracking MSE at most `threshold` x PD alone's in the same window; "
                                "reached (t_reach_s) when consecutive windows stay at it for `sustain` seconds",
        "control_rate_hz": C.RATE, "period_us": PERIOD_US, "kp": kp.tolist(), "kd": kd.tolist(),
        **environment.hardware(), "versions": environment.versions()})
    return curves, summary
