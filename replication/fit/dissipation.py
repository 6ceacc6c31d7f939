"""What a fit with a learned Rayleigh dissipation (`ModelSpec.dissipation`) says of the friction:
`dissipation_metrics(f, r, name, system, out, rollouts=None)` adds to the evaluation `out` of the fitted model
`f` on the rows `r` of set `name` the coefficients b and, where they can be read in the system's units, the
friction. `rollouts` ({"horizon", "substeps"}, as the evaluation rolled the set out; None where it did not)
decides how the friction is checked: on rollouts where the set has them (`BRACKET`), else on one-step errors
(`ABLATION_MIN`). `GATE` names the rule in a fit's eval_config, so that a fit checked by another is evaluated
again."""
from __future__ import annotations

import dataclasses

import numpy as np

from lagbench.replication.evaluation.adapters import adapter
from lagbench.replication.evaluation.metrics import heldout_errors
from lagbench.replication.fit.competence import competence
from lagbench.replication.fit.load import Padded
from lagbench.replication.fit.rollout_groups import mean_state_error

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

# On a set of whole trajectories the one-step ablation fails where the targets are noisy: on a double pendulum
# recorded at 0.5 degree of noise the exact dynamics themselves read 1.03, their one-step errors being the
# estimated q-double-dot's noise (docs/lab/recording_defaults.md). Rollouts integrate the friction and see it:
# there the friction is read only where it is bracketed, the rollout error (S_rollout_gmean_err) with every
# coefficient halved and with every coefficient doubled each at least `BRACKET_MIN` x the error with the learned
# ones. Measured on that recording's two fits (docs/lab/friction_gate/README.md): their own frictions, within
# 14 % of the truth, read 1.13-1.28 (halved) and 1.37-1.42 (doubled) on the 4 s test trajectories; the
# same models with their coefficients scaled by 0.3, 0.5, 0.7, 2 or 3, or to 0.02 and 0.42 of their own (as a
# fit that read 0.004 and 0.084 against the true 0.2), read under 1 on the side of the truth; a model whose
# dissipation is removed reads 1.000 both ways. The bracket checks the friction's overall scale: one
# coefficient at 0.4 of its own, the other kept, still passed.
BRACKET = (0.5, 2.0)
BRACKET_MIN = 1.02
GATE = (f"rollouts with b x {BRACKET[0]:g} and x {BRACKET[1]:g} >= {BRACKET_MIN:g} x; else one-step ablation >= "
        f"{ABLATION_MIN:g}; read for an LNN and a DeLaN fitted to accelerations")
OFF = -50.0   # a raw coefficient whose softplus, about 2e-22, is no friction at all


def dissipation_metrics(f, r, name, system, out, rollouts: dict | None = None) -> None:
    """A dissipative model's Rayleigh coefficients b = softplus(raw) (the Lagrangian's own scale), and for an LNN
    or a DeLaN fitted to accelerations with a system the coefficients in the system's units: a Lagrangian learned
    from accelerations is fixed only up to a factor c (of either sign), its velocity Hessian H = c M
    (`kinetic_matrix`: a DeLaN's is its mass matrix), so the friction the data obey is b / |c|, c the
    least-squares factor of H against the system's mass matrix M over S's states (S_dissipation_scale), given
    where the model learned (`competence`, on S's one-step error), H is close to c M
    (S_dissipation_hessian_residual at most `HESSIAN_RESIDUAL_MAX`) and the friction is what the data show: with
    `rollouts`, bracketed by them (S_dissipation_bracket_half, S_dissipation_bracket_double: the rollout error
    with b x `BRACKET` over that with b, each at least `BRACKET_MIN`), else carrying the model's one-step
    accuracy (S_dissipation_ablation, its one-step error without the dissipation over that with it, at least
    `ABLATION_MIN`; recorded either way)."""
    b = softplus(f.params["dissipation.raw"])
    out.metrics.update({f"dissipation_b{k}": float(v) for k, v in enumerate(b)})
    if f.spec.kind == "delan" and f.task == "inverse_dynamics":   # fitted to torques: b is in their units
        out.metrics.update({f"{name}_dissipation_coefficient_{k}": float(v) for k, v in enumerate(b)})
    if system is None or f.spec.kind not in ("lnn", "delan") or f.task == "inverse_dynamics":
        return   # an HNN's b is per unit of its momentum, qdot as it trained
    q, qd = r["q"][:KEEP], r["qdot"][:KEEP]
    h, m = kinetic_matrix(f, q, qd), system.mass_matrix(q)
    c = float(np.sum(h * m) / np.sum(m * m))
    residual = float(np.linalg.norm(h - c * m) / np.linalg.norm(h))
    out.metrics[f"{name}_dissipation_scale"] = c
    out.metrics[f"{name}_dissipation_hessian_residual"] = residual
    ablation = out.metrics[f"{name}_dissipation_ablation"] = without_dissipation_l1(f, r) / out.metrics[f"{name}_l1"]
    learned = competence(out.metrics, f"{name}_l1")
    why = ("the model is not clearly better than the null predictor" if not (learned and learned["learned"]) else
           f"the learned velocity Hessian is no multiple of the system's mass matrix (residual {residual:.2f} > "
           f"{HESSIAN_RESIDUAL_MAX})" if residual > HESSIAN_RESIDUAL_MAX else
           _unbracketed(f, r, name, out, rollouts) if rollouts is not None else
           f"the friction does not carry the model's accuracy (its error without the dissipation is {ablation:.2f} x "
           f"that with it, under {ABLATION_MIN})" if ablation < ABLATION_MIN else None)
    if why:   # an untrained model's b / |c| can land anywhere, even near the truth
        out.counters[f"{name}_dissipation_coefficient"] = f"not estimated: {why}"
        return
    out.metrics.update({f"{name}_dissipation_coefficient_{k}": float(v / abs(c)) for k, v in enumerate(b)})


def kinetic_matrix(f, q, qd) -> np.ndarray:
    """The fitted model's velocity Hessian of its Lagrangian at the states (q, qd): an LNN's through its
    network, a DeLaN's its mass matrix M(q) (its Lagrangian is quadratic in qdot)."""
    h = f.model.mass_matrix(q) if f.spec.kind == "delan" else f.model.velocity_hessian(q, qd)
    return np.asarray(h, np.float64)


def _unbracketed(f, r, name, out, rollouts) -> str | None:
    """Why the rollouts do not bracket the learned friction (None: they do); the ratios into `out`."""
    base = out.metrics.get(f"{name}_rollout_gmean_err")
    ratios = bracket_ratios(f, r, softplus(f.params["dissipation.raw"]), rollouts.get("horizon"), rollouts["substeps"],
                            base)
    out.metrics[f"{name}_dissipation_bracket_half"], out.metrics[f"{name}_dissipation_bracket_double"] = ratios
    if all(x >= BRACKET_MIN for x in ratios):
        return None
    return (f"the rollouts do not single out the learned friction (their error with its coefficients x "
            f"{BRACKET[0]:g} is {ratios[0]:.3g} x, x {BRACKET[1]:g} {ratios[1]:.3g} x that with them; both must be "
            f"at least {BRACKET_MIN:g})")


def bracket_ratios(f, r, b, horizon=None, substeps=2, base=None) -> list[float]:
    """The rollout error on the rows `r` of the fitted model `f` with coefficients b x each of `BRACKET`, over
    its error with b (`base` where already measured, as the evaluation's S_rollout_gmean_err with b as learned)."""
    if base is None:
        base = mean_state_error(with_coefficients(f, b), r, horizon, substeps)
    return [mean_state_error(with_coefficients(f, k * b), r, horizon, substeps) / base if base > 0 else float("nan")
            for k in BRACKET]


def softplus(raw) -> np.ndarray:
    return np.log1p(np.exp(np.asarray(raw, np.float64)))


def with_coefficients(f, b):
    """The fitted model `f` with its Rayleigh coefficients set to `b` (>= 0; 0 removes the dissipation)."""
    raw = np.asarray(f.params["dissipation.raw"])
    b = np.asarray(b, np.float64)
    new = np.where(b > 0, np.log(np.expm1(np.maximum(b, 1e-300))), OFF).astype(raw.dtype)
    params = {**f.params, "dissipation.raw": new}
    return dataclasses.replace(f, params=params, model=Padded(adapter(f.framework, f.spec, params)))


def without_dissipation_l1(f, r) -> float:
    """The one-step L1 on the rows `r` of the fitted model `f` with its dissipation removed (b = 0)."""
    b, pred = with_coefficients(f, np.zeros(np.shape(f.params["dissipation.raw"]))).one_step(r)
    return heldout_errors(pred, b["target"])["l1"]
