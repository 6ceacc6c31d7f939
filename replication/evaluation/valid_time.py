"""Valid prediction time (VPT), the chaos floor and the Lyapunov time of a set of rollouts.

On a chaotic system a mean state error over a fixed horizon mixes the model's error with chaos; the field
reports how long a prediction stays valid, against what chaos itself allows.

`normalised_rmse(z_pred, z_true)` (B, T): per trajectory and time, sqrt(mean over the state's components of
(pred - true)^2 / var_c), var_c the variance of component c of the true states over every trajectory and
time (the state's spread); a non-finite prediction counts as +inf.
`valid_time(err, t, threshold)` (B,): the first time `err` exceeds `threshold`; the horizon t[-1] where it
never does (censored: `valid_times` records the share that was).
Two conventions are in use: normalised RMSE 0.4 (`VPT_NRMSE`, the one reported as `vpt_s`) and normalised MSE
0.025 (`VPT_NMSE`, recorded as `vpt_nmse_s`: the RMSE crossing sqrt(0.025) = 0.158).
`lyapunov_time(err_floor, t, perturbation)` (B,): 1 / the largest Lyapunov exponent, estimated from the truth
against the truth from a start perturbed by `PERTURBATION`: the least-squares slope of log(separation)
against time while it grows from 100 x its start to 1e-2 of the spread; NaN where it did not grow by four
decades within the horizon (not chaotic at that energy, or too short a horizon).
"""
from __future__ import annotations

import numpy as np

VPT_NRMSE = 0.4
VPT_NMSE = 0.025
PERTURBATION = 1e-8   # added to the initial angles of the chaos floor's truth
_GROWTH = 1e4         # the separation must grow this much for a Lyapunov time


def normalised_rmse(z_pred, z_true, var=None):
    """`var`: the components' variances (default: of `z_true`), for sets rolled out in parts."""
    z_pred, z_true = np.asarray(z_pred, np.float64), np.asarray(z_true, np.float64)
    var = np.var(z_true.reshape(-1, z_true.shape[-1]), axis=0) if var is None else np.asarray(var, np.float64)
    var = np.where(var > 0, var, 1.0)
    with np.errstate(over="ignore", invalid="ignore"):
        err = np.sqrt(np.mean((z_pred - z_true) ** 2 / var, axis=-1))
    return np.where(np.isfinite(err), err, np.inf)


def valid_time(err, t, threshold: float):
    """(B,) the first time of each row of `err` (B, T) above `threshold`; t[-1] where none is."""
    above = np.asarray(err) > threshold
    first = np.argmax(above, axis=1)
    return np.where(above.any(axis=1), np.asarray(t)[first], np.asarray(t)[-1])


def lyapunov_time(err_floor, t):
    """(B,) 1 / the largest Lyapunov exponent per trajectory, from the floor's separation (B, T); NaN where
    it did not grow by `_GROWTH` before reaching 1e-2."""
    t = np.asarray(t, np.float64)
    out = np.full(len(err_floor), np.nan)
    for b, e in enumerate(np.asarray(err_floor, np.float64)):
        start = e[0] if e[0] > 0 else np.nan
        window = (e >= 100 * start) & (e <= 1e-2) & np.isfinite(e)
        if not np.isfinite(start) or window.sum() < 3 or e[window].max() < _GROWTH * start:
            continue
        slope = np.polyfit(t[window], np.log(e[window]), 1)[0]
        out[b] = 1.0 / slope if slope > 0 else np.nan
    return out


def valid_times(t, z_pred, z_true, z_floor) -> tuple[dict, dict]:
    """Metrics {vpt_s, vpt_nmse_s, vpt_censored, chaos_floor_vpt_s, lyapunov_time_s, vpt_lyapunov,
    chaos_floor_vpt_lyapunov} (medians over trajectories; the Lyapunov ones NaN where no trajectory gave a
    Lyapunov time) and per-trajectory columns for rollouts.csv."""
    err, floor = normalised_rmse(z_pred, z_true), normalised_rmse(z_floor, z_true)
    vpt, vpt_mse = valid_time(err, t, VPT_NRMSE), valid_time(err, t, np.sqrt(VPT_NMSE))
    floor_vpt, lyap = valid_time(floor, t, VPT_NRMSE), lyapunov_time(floor, t)
    lt = float(np.nanmedian(lyap)) if np.isfinite(lyap).any() else float("nan")
    metrics = {"vpt_s": float(np.median(vpt)), "vpt_nmse_s": float(np.median(vpt_mse)),
               "vpt_censored": float(np.mean(~(err > VPT_NRMSE).any(axis=1))),
               "chaos_floor_vpt_s": float(np.median(floor_vpt)), "lyapunov_time_s": lt,
               "vpt_lyapunov": float(np.median(vpt)) / lt, "chaos_floor_vpt_lyapunov": float(np.median(floor_vpt)) / lt}
    columns = {"vpt_s": vpt, "vpt_nmse_s": vpt_mse, "chaos_floor_vpt_s": floor_vpt, "lyapunov_time_s": lyap}
    return metrics, columns
