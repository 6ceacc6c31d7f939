"""Metrics of the SPEC, in NumPy, shared by both frameworks.

Shapes: trajectories (B, T, k); energies (B, T).
- one-step: `heldout_errors(pred, target, weight)` -> l1 (per-sample sum |err|, mean or 1+gamma
  weighted mean as the original code) and mse (per-sample sum err^2, mean).
- rollout: `bounded_relative_error(z_pred, z_true)` = |z_pred - z_true| / (|z_pred| + |z_true|) per step
  (B, T); `geometric_mean_over_time` of it per trajectory (B,), skipping t = 0 where it is 0.
- energy: `energy_errors(E_pred, E_true, scale)` -> |E_pred - E_true| / scale at the final step and
  the max over time, each averaged over trajectories (diverged trajectories count as +inf in the max
  and are reported separately).
"""
from __future__ import annotations

import numpy as np

from replication.objective import loss_value


def heldout_errors(pred, target, weight=None) -> dict:
    pred, target = np.asarray(pred, np.float64), np.asarray(target, np.float64)
    w = None if weight is None else np.asarray(weight, np.float64)
    return {"l1": float(loss_value(pred, target, w, "l1")), "mse": float(loss_value(pred, target, w, "mse"))}


def bounded_relative_error(z_pred, z_true):
    """In [0, 1]; a diverged (non-finite) prediction counts as 1, the bound."""
    num = np.linalg.norm(z_pred - z_true, axis=-1)
    den = np.linalg.norm(z_pred, axis=-1) + np.linalg.norm(z_true, axis=-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        err = np.where(den > 0, num / den, 0.0)
    return np.where(np.isfinite(num) & np.isfinite(den), err, 1.0)


def geometric_mean_over_time(err, floor=1e-16):
    e = np.asarray(err)[:, 1:]
    return np.exp(np.mean(np.log(np.maximum(e, floor)), axis=1))


def energy_errors(E_pred, E_true, scale) -> dict:
    d = np.abs(np.asarray(E_pred) - np.asarray(E_true)) / scale
    diverged = ~np.all(np.isfinite(d), axis=1)
    ok = ~diverged
    final = float(np.mean(d[ok, -1])) if ok.any() else float("nan")
    mx = float(np.mean(np.max(d[ok], axis=1))) if ok.any() else float("nan")
    return {"energy_err_final": final, "energy_err_max": mx, "n_diverged": int(diverged.sum()),
            "n_trajectories": int(d.shape[0])}
