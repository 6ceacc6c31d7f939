"""Learning online while tracking, as a claim (claim 13): the unit's model starts untrained and learns from the
samples of its own control loop, the loop of `replication.studies.online` (computed-torque control of the
two-link arm at 500 Hz; a replay buffer; `steps` optimiser steps of `batch` every `every` ticks).

For the unit's seed the routine builds the study's learner (`online_learner.learner`: claim 9's model of the
unit's kind at the unit's widths, initialised from the seed, with the learner's fixed optimiser settings) and
runs `online.run_online` on `seconds` of simulated time of the training family's references
(`online.sequence`), then scores the frozen final model on `n_unseen` references of `unseen_duration` seconds
of the unseen family (`online.unseen`). Both draws use generator seed `control.SEED` + the split's draw offset
(as `evaluation.control` does), so the test split learns and is scored on references no choice has seen. PD
alone runs the same references (computed once per references and cached, as `evaluation.control` caches its
floors). With `ctx.model` given (a fixed model: the null-model tests), that model is the feed-forward and
nothing learns: a zero model is PD alone, a diverging one diverges.

Settings (`cfg`, the claim's evaluation config; defaults `DEFAULTS`, the study's): seconds, every, steps,
batch, buffer, window, threshold, sustain, n_unseen, unseen_duration, and tail (the share of the run's last
windows the competence bar reads).

Metrics: `t_reach_s` (the sustained crossing: the end of the first window of the first run of consecutive
windows whose tracking MSE is at most `threshold` x PD alone's in the same window, lasting at least `sustain`
seconds, `online.sustain_start`; +inf: never, and a run the end of the run cuts short does not count),
`t_first_cross_s` (the end of the first window at the threshold, however briefly; +inf: never; recorded, not
decided), `t_settle_s` (the end of the first window from which every later one is at it;
+inf: never), `first_window_mse`, `final_window_mse` and `null_final_window_mse` (PD alone's), `final_ratio_to_pd`,
`tail_mse` and `null_tail_mse` (the mean window MSE over the last `tail` of the windows, at least one, and PD
alone's over the same windows: the competence bar's, steadier than one window of a learner whose error still
jumps from window to window), `unseen_mse` and `null_unseen_mse` (PD alone on the unseen
references; +inf if a reference diverged), `unseen_ratio_to_pd`, `n_diverged` (references that diverged, in
the loop and unseen), `n_diverged_ticks` (the loop's ticks skipped after a divergence), `steps` (optimiser steps
taken), and compute per tick in microseconds: `inference_us_mean`, `learning_us_mean`, `compute_us_mean`,
`compute_us_p99` (wall-clock on the run's machine: reported, never decided). A window with a diverged tick
counts as +inf (as `evaluation.control` counts a diverged reference), so it is never at the threshold.
Arrays: per window, `window_end` (s), `window_mse`, `pd_window_mse` and `window_ratio` (to PD alone).
"""
from __future__ import annotations

import math
from functools import lru_cache

import numpy as np
import pandas as pd

from lagbench.replication.evaluation.routines import Evaluation
from lagbench.replication.studies import control as C
from lagbench.replication.studies import online as O
from lagbench.replication.training.objective import predict

DEFAULTS = {"seconds": 30.0, "every": O.EVERY, "steps": O.STEPS, "batch": O.BATCH, "buffer": O.BUFFER,
            "window": O.WINDOW, "threshold": O.THRESHOLD, "sustain": O.SUSTAIN, "n_unseen": O.N_UNSEEN,
            "unseen_duration": C.DURATION, "tail": 0.25}
LEARNERS = {"delan": "delan", "baseline": "ff"}   # model kind -> the online learner's kind
SUMMARY = (*O.TIMES, "first_window_mse", "final_window_mse", "final_ratio_to_pd",
           "inference_us_mean", "learning_us_mean", "compute_us_mean", "compute_us_p99")


def settings(cfg: dict) -> dict:
    return {k: type(v)(cfg.get(k, v)) for k, v in DEFAULTS.items()}


class Fixed:
    """A model that does not learn, as the loop's controller: its predicted torque is the feed-forward."""

    def __init__(self, model, kind: str, task: str):
        self.model, self.kind, self.task = model, kind, task

    def inverse(self, q, qdot, qddot) -> np.ndarray:
        batch = {"q": q, "qdot": qdot, "extra": qddot}
        return np.asarray(predict(self.model, self.kind, self.task, batch, np.concatenate), np.float64)

    def tau(self, q, qdot, qddot) -> np.ndarray:
        return self.inverse(q[None], qdot[None], qddot[None])[0]


@lru_cache(maxsize=4)
def _references(seconds: float, seed: int) -> dict:
    return O.sequence("train", seconds, seed=seed)


@lru_cache(maxsize=4)
def _pd_alone(seconds: float, window: float, seed: int) -> pd.DataFrame:
    windows, _ = O.run_online(None, _references(seconds, seed), window=window, seconds=seconds)
    return pd.DataFrame(windows)


@lru_cache(maxsize=4)
def _pd_unseen(n_unseen: int, duration: float, seed: int) -> dict:
    return O.unseen(None, n_unseen, duration, seed)


def _controller(ctx, s: dict):
    """(controller, optimiser steps per learning tick): a fixed model (no steps), else a fresh learner."""
    if ctx.model is not None:
        return Fixed(ctx.model, ctx.spec.kind, ctx.protocol.task), 0
    from lagbench.replication.studies.online_learner import learner

    if ctx.spec.kind not in LEARNERS:
        raise ValueError(f"online learning: model kind {ctx.spec.kind!r}; valid {', '.join(LEARNERS)}")
    # the learner learns at the unit's protocol's rate and widths (claim 9's unless a search chose otherwise)
    return (learner(LEARNERS[ctx.spec.kind], ctx.framework, int(ctx.seed), tuple(ctx.spec.hidden),
                    lr=ctx.protocol.schedule.lr), s["steps"])


def _windows(windows: list, pd_windows: pd.DataFrame) -> pd.DataFrame:
    """The loop's windows with their ratio to PD alone; a window with a diverged tick at +inf."""
    w = pd.DataFrame(windows)
    w.loc[w["n_diverged"] > 0, "track_mse"] = math.inf
    w["ratio_to_pd"] = O.ratio_to_pd(w, pd_windows)
    return w


def eval_online(ctx) -> Evaluation:
    from lagbench.replication.run.environment import torch_threads

    s, seed = settings(ctx.cfg), C.SEED + ctx.split.draw_offset
    refs, pd_w = _references(s["seconds"], seed), _pd_alone(s["seconds"], s["window"], seed)
    ctrl, steps = _controller(ctx, s)
    total, done = int(round(s["seconds"] * C.RATE)), [0]

    def progress(n):
        done[0] += n
        if ctx.progress:
            ctx.progress("learning online", done[0], total)

    with torch_threads(1 if ctx.framework == "torch" and ctx.model is None else None):
        windows, ticks = O.run_online(ctrl, refs, s["every"], steps, s["batch"], s["buffer"], s["window"],
                                      seed=int(ctx.seed), seconds=s["seconds"], progress=progress)
        scores = O.unseen(ctrl, s["n_unseen"], s["unseen_duration"], seed)
    w = _windows(windows, pd_w)
    row = O.summary_row(w, ticks, s["threshold"], s["window"], s["sustain"])
    null = _pd_unseen(s["n_unseen"], s["unseen_duration"], seed)
    bad = scores["unseen_diverged"] > 0
    out = Evaluation()
    m = out.metrics
    m.update({k: math.inf if k in O.TIMES and math.isnan(row[k]) else row[k] for k in SUMMARY})
    m["null_final_window_mse"] = float(pd_w["track_mse"].iloc[-1])
    tail = max(1, math.ceil(s["tail"] * len(w) - 1e-9))
    m["tail_mse"] = float(w["track_mse"].iloc[-tail:].mean())
    m["null_tail_mse"] = float(pd_w["track_mse"].iloc[-tail:].mean())
    m["unseen_mse"] = math.inf if bad else scores["unseen_mse"]
    m["null_unseen_mse"] = null["unseen_mse"]
    m["unseen_ratio_to_pd"] = m["unseen_mse"] / null["unseen_mse"]
    m["n_diverged"] = int(ticks["diverged_refs"] + scores["unseen_diverged"])
    m["n_diverged_ticks"] = int(w["n_diverged"].sum())
    m["steps"] = int(w["steps"].iloc[-1])
    out.arrays.update(window_end=w["t_start"].to_numpy(float) + s["window"], window_mse=w["track_mse"].to_numpy(float),
                      pd_window_mse=pd_w["track_mse"].to_numpy(float), window_ratio=w["ratio_to_pd"].to_numpy(float))
    return out
