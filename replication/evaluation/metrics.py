"""Metrics of the SPEC, in NumPy, shared by both frameworks.

Shapes: trajectories (B, T, k); energies (B, T).
- one-step: `heldout_errors(pred, target, weight)` -> l1 (per-sample sum |err|, mean or 1+gamma
  weighted mean as the original code) and mse (per-sample sum err^2, mean).
- rollout: `bounded_relative_error(z_pred, z_true)` = |z_pred - z_true| / (|z_pred| + |z_true|) per step
  (B, T); `geometric_mean_over_time` of it per trajectory (B,), skipping t = 0 where it is 0.
- energy: `energy_errors(E_pred, E_true, scale)` -> |E_pred - E_true| / scale at the final step and
  the max over time, each averaged over trajectories; a diverged trajectory counts as +inf, so one
  blow-up makes the mean +inf. Beside them: the median final error (diverged = +inf), the mean over
  the finite trajectories only (for display, never for a verdict) and the count of diverged ones.
- null predictors: `null_errors(target, weight)` -> the held-out l1 and mse of the better of two
  predictors that learned nothing (zero, and the held-out mean target); the competence bars' yardstick.
Arrays of the wrong rank, mismatched shapes or no samples raise ValueError naming the problem.
"""
from __future__ import annotations

import numpy as np

from lagbench.replication.training.objective import loss_value


def _same_shape(what: str, a, b, ndim: int, min_len=(1,)):
    a, b = np.asarray(a, np.float64), np.asarray(b, np.float64)
    if a.shape != b.shape or a.ndim != ndim or any(n < m for n, m in zip(a.shape, min_len, strict=False)):
        raise ValueError(f"{what}: expected two arrays of the same shape with {ndim} dimensions and at least "
                         f"{min_len} entries along the first axes; got {a.shape} and {b.shape}")
    return a, b


def heldout_errors(pred, target, weight=None) -> dict:
    pred, target = np.asarray(pred, np.float64), np.asarray(target, np.float64)
    pred, target = _same_shape("heldout_errors (pred, target)", pred, target, max(pred.ndim, 1), (1, 1))
    w = None if weight is None else np.asarray(weight, np.float64)
    if w is not None and w.shape != pred.shape[:1]:
        raise ValueError(f"heldout_errors: weight must have shape {pred.shape[:1]}, got {w.shape}")
    return {"l1": float(loss_value(pred, target, w, "l1")), "mse": float(loss_value(pred, target, w, "mse"))}


def bounded_relative_error(z_pred, z_true):
    """In [0, 1]; a diverged (non-finite) prediction counts as 1, the bound."""
    z_pred, z_true = np.asarray(z_pred), np.asarray(z_true)
    if z_pred.shape != z_true.shape or z_pred.ndim < 1:
        raise ValueError(f"bounded_relative_error: shapes must match (..., k); got {z_pred.shape} and {z_true.shape}")
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):   # a huge prediction's norms overflow to inf
        num = np.linalg.norm(z_pred - z_true, axis=-1)
        den = np.linalg.norm(z_pred, axis=-1) + np.linalg.norm(z_true, axis=-1)
        err = np.where(den > 0, num / den, 0.0)
    return np.where(np.isfinite(num) & np.isfinite(den), err, 1.0)


def geometric_mean_over_time(err, floor=1e-16):
    e = np.asarray(err)
    if e.ndim != 2 or e.shape[1] < 2:
        raise ValueError(f"geometric_mean_over_time: expected errors (B, T) with T >= 2; got shape {e.shape}")
    e = e[:, 1:]
    return np.exp(np.mean(np.log(np.maximum(e, floor)), axis=1))


def energy_errors(E_pred, E_true, scale) -> dict:
    E_pred, E_true = _same_shape("energy_errors (E_pred, E_true)", E_pred, E_true, 2, (0, 1))
    if not (np.isfinite(scale) and scale > 0):
        raise ValueError(f"energy_errors: scale must be positive and finite, got {scale!r}")
    with np.errstate(invalid="ignore", over="ignore"):
        d = np.abs(E_pred - E_true) / scale
    diverged = ~np.all(np.isfinite(d), axis=1)
    ok = ~diverged
    final = np.where(diverged, np.inf, d[:, -1])
    mx = np.where(diverged, np.inf, np.max(np.where(np.isfinite(d), d, 0.0), axis=1))
    nan = float("nan")
    return {"energy_err_final": float(np.mean(final)) if len(d) else nan,
            "energy_err_max": float(np.mean(mx)) if len(d) else nan,
            # the median over every trajectory (a diverged one counts as +inf): robust to one blown-up rollout
            "energy_err_final_median": float(np.median(final)) if len(d) else nan,
            # the spread over initial conditions beside the median (a diverged one ranks last)
            "energy_err_final_q25": float(np.quantile(final, 0.25, method="lower")) if len(d) else nan,
            "energy_err_final_q75": float(np.quantile(final, 0.75, method="higher")) if len(d) else nan,
            "energy_err_final_finite": float(np.mean(final[ok])) if ok.any() else nan,
            "n_diverged": int(diverged.sum()),
            "n_trajectories": int(d.shape[0])}


def null_errors(target, weight=None) -> dict:
    """Held-out l1 and mse (as `heldout_errors`) of the better of predicting 0 and predicting the mean target."""
    target = np.asarray(target, np.float64)
    zero = heldout_errors(np.zeros_like(target), target, weight)
    mean = heldout_errors(np.broadcast_to(target.mean(0), target.shape), target, weight)
    return {k: min(zero[k], mean[k]) for k in zero}
