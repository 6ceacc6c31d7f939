"""Closed-loop tracking by a unit's learned inverse model (claim 12): the DeLaN paper's control experiment.

The unit's model gives the feed-forward torque of the computed-torque controller of
`replication.studies.control` (tau = tau_hat(q_d, qdot_d, qddot_d) + KP (q_d - q) + KD (qdot_d - qdot) at
500 Hz, torque held over each period, the SymPy two-link arm as the plant, integrated by RK4 in float64
independently of the controller), on `n_refs` references of `duration` seconds of each family in
`FAMILIES`: "train" (the family the models trained on, new references: the competence bar's), "test" (the
unseen family) and "train_x2" (the training family twice as fast). The references are drawn from
`control.SEED` + the split's draw offset, so the test split tracks references no choice has seen. The three
families share their ticks, so each controller tracks all of them in one batch.

Metrics per family f: `tracking_mse_<f>` (mean over references and ticks of the squared joint-angle error
summed over joints; +inf if any reference diverged, as the energy claims count a diverged rollout),
`tracking_mse_<f>_joint<j>`, `torque_effort_<f>` (mean squared torque), `n_diverged_<f>`, and the two
controllers every unit is compared with: `null_tracking_mse_<f>` (PD alone, tau_hat = 0: the null
controller the competence bar reads) and `truth_tracking_mse_<f>` (the true inverse dynamics: the best any
model can give, its error the zero-order hold's). `n_diverged` sums the families. Arrays: the first test
reference and the unit's response to it (`test_t`, `test_q_ref`, `test_q`), for the report.
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np

from lagbench.replication.evaluation.routines import Evaluation
from lagbench.replication.studies import control
from lagbench.replication.training.objective import predict

FAMILIES = ("train", "test", "train_x2")
N_REFS, DURATION = control.N_REFS, control.DURATION


@lru_cache(maxsize=8)
def _references(n_refs: int, duration: float, seed: int) -> tuple[dict, dict]:
    """Every family's references stacked into one batch (they share the ticks), and each family's slice of
    it: a controller is simulated once for all three families."""
    per = {family: control.references(family, n_refs, duration, seed=seed) for family in FAMILIES}
    refs = {k: np.concatenate([per[f][k] for f in FAMILIES]) for k in ("q", "qdot", "qddot")}
    refs["t"] = per[FAMILIES[0]]["t"]
    return refs, {f: slice(i * n_refs, (i + 1) * n_refs) for i, f in enumerate(FAMILIES)}


def _family(d: dict, rows: slice) -> dict:
    """One family's part of a stacked reference batch or simulation."""
    return {k: v if k == "t" else v[rows] for k, v in d.items()}


@lru_cache(maxsize=8)
def _floors(n_refs: int, duration: float, seed: int) -> dict:
    """family -> (PD alone's scores, the true inverse dynamics' scores) on the family's references."""
    from lagbench import systems

    (refs, rows), plant = _references(n_refs, duration, seed), systems.get("two_link_arm")
    pd = control.track(None, refs)
    truth = control.track(lambda q, v, a: plant.inverse_dynamics(q, v, a), refs)
    return {f: tuple(control.scores(_family(sim, r), _family(refs, r)) for sim in (pd, truth)) for f, r in rows.items()}


def eval_control(ctx) -> Evaluation:
    cfg, m, kind, task = ctx.cfg, ctx.model, ctx.spec.kind, ctx.protocol.task
    n_refs, duration = int(cfg.get("n_refs", N_REFS)), float(cfg.get("duration", DURATION))
    seed = control.SEED + ctx.split.draw_offset

    def inverse(q, v, a):
        return np.asarray(predict(m, kind, task, {"q": q, "qdot": v, "extra": a}, np.concatenate), float)

    out, diverged = Evaluation(), 0
    stacked, rows = _references(n_refs, duration, seed)
    if ctx.progress:
        ctx.progress("tracking", 0, 1)
    sim_all = control.track(inverse, stacked)
    floors = _floors(n_refs, duration, seed)
    for family in FAMILIES:
        refs, sim = _family(stacked, rows[family]), _family(sim_all, rows[family])
        s = control.scores(sim, refs)
        pd, truth = floors[family]
        bad = s["n_diverged"] > 0
        out.metrics[f"tracking_mse_{family}"] = float("inf") if bad else s["track_mse"]
        for j in range(refs["q"].shape[-1]):
            out.metrics[f"tracking_mse_{family}_joint{j}"] = float("inf") if bad else s[f"track_mse_joint{j}"]
        out.metrics[f"torque_effort_{family}"] = s.get("torque_effort", float("nan"))
        out.metrics[f"n_diverged_{family}"] = s["n_diverged"]
        out.metrics[f"null_tracking_mse_{family}"] = pd["track_mse"]
        out.metrics[f"truth_tracking_mse_{family}"] = truth["track_mse"]
        diverged += s["n_diverged"]
        if family == "test":
            out.arrays.update(test_t=refs["t"], test_q_ref=refs["q"][0], test_q=sim["q"][0])
    if ctx.progress:
        ctx.progress("tracking", 1, 1)
    out.metrics["n_diverged"] = diverged
    return out
