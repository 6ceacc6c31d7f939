"""What a fit with a learned Rayleigh dissipation (`ModelSpec.dissipation`) says of the friction:
`dissipation_metrics(f, r, name, system, out)` adds to the evaluation `out` of the fitted model `f` on the
rows `r` of set `name` the coefficients b and, where they can be read in the system's units, the friction."""
from __future__ import annotations

import dataclasses

import numpy as np

from lagbench.replication.evaluation.adapters import adapter
from lagbench.replication.evaluation.metrics import heldout_errors
from lagbench.replication.fit.competence import competence
from lagbench.replication.fit.load import Padded

KEEP = 2000   # states of the set (at most) the velocity Hessian is compared on


# the friction in the system's units is read off b / |c| only where the learned velocity Hessian is close to
# c M: a relative residual |H - c M| / |H| above this says the Lagrangian's kinetic part is not the system's
# (measured: 0.10 for the pendulum example's fit, 0.32 for a double pendulum fit at 0.23 x the null's error,
# 0.998 for a 5-step fit, whose b / |c| came out 0.25 against the true 0.2)
HESSIAN_RESIDUAL_MAX = 0.5

# ... and only where the learned friction carries the model's accuracy: its one-step error on the set with
# the dissipation removed (b = 0) at least this many times its error with it. A model whose error is several
# times the friction's share of q-double-dot leaves the friction unidentified (measured on the friction double
# pendulum, docs/lab/fit_friction_dp.md: fits at 2.6 and 1.35 x read 0.20-0.21 against the true 0.2, a fit
# at 1.03 x read 0.004 and 0.084)
ABLATION_MIN = 1.1
OFF = -50.0   # a raw coefficient whose softplus, about 2e-22, is no friction at all


def dissipation_metrics(f, r, name, system, out) -> None:
    """A dissipative LNN's Rayleigh coefficients b = softplus(raw) (the Lagrangian's own scale), and with a
    system the coefficients in the system's units: a Lagrangian learned from accelerations is fixed only up to
    a factor c (of either sign), its velocity Hessian H = c M, so the friction the data obey is b / |c|, c the
    least-squares factor of H against the system's mass matrix M over S's states (S_dissipation_scale), given
    where the model learned (`competence`, on S's one-step error), H is close to c M
    (S_dissipation_hessian_residual at most `HESSIAN_RESIDUAL_MAX`) and the friction carries the model's accuracy
    (S_dissipation_ablation, its one-step error without the dissipation over that with it, at least
    `ABLATION_MIN`)."""
    b = np.log1p(np.exp(np.asarray(f.params["dissipation.raw"], np.float64)))
    out.metrics.update({f"dissipation_b{k}": float(v) for k, v in enumerate(b)})
    if f.spec.kind == "delan" and f.task == "inverse_dynamics":   # fitted to torques: b is in their units
        out.metrics.update({f"{name}_dissipation_coefficient_{k}": float(v) for k, v in enumerate(b)})
    if system is None or f.spec.kind != "lnn":   # an HNN's b is per unit of its momentum, qdot as it trained
        return
    q, qd = r["q"][:KEEP], r["qdot"][:KEEP]
    h, m = np.asarray(f.model.velocity_hessian(q, qd), np.float64), system.mass_matrix(q)
    c = float(np.sum(h * m) / np.sum(m * m))
    residual = float(np.linalg.norm(h - c * m) / np.linalg.norm(h))
    out.metrics[f"{name}_dissipation_scale"] = c
    out.metrics[f"{name}_dissipation_hessian_residual"] = residual
    ablation = out.metrics[f"{name}_dissipation_ablation"] = without_dissipation_l1(f, r) / out.metrics[f"{name}_l1"]
    learned = competence(out.metrics, f"{name}_l1")
    why = ("the model is not clearly better than the null predictor" if not (learned and learned["learned"]) else
           f"the learned velocity Hessian is no multiple of the system's mass matrix (residual {residual:.2f} > "
           f"{HESSIAN_RESIDUAL_MAX})" if residual > HESSIAN_RESIDUAL_MAX else
           f"the friction does not carry the model's accuracy (its error without the dissipation is {ablation:.2f} x "
           f"that with it, under {ABLATION_MIN})" if ablation < ABLATION_MIN else None)
    if why:   # an untrained model's b / |c| can land anywhere, even near the truth
        out.counters[f"{name}_dissipation_coefficient"] = f"not estimated: {why}"
        return
    out.metrics.update({f"{name}_dissipation_coefficient_{k}": float(v / abs(c)) for k, v in enumerate(b)})


def without_dissipation_l1(f, r) -> float:
    """The one-step L1 on the rows `r` of the fitted model `f` with its dissipation removed (b = 0)."""
    params = {**f.params, "dissipation.raw": np.full_like(np.asarray(f.params["dissipation.raw"]), OFF)}
    g = dataclasses.replace(f, params=params, model=Padded(adapter(f.framework, f.spec, params)))
    b, pred = g.one_step(r)
    return heldout_errors(pred, b["target"])["l1"]
