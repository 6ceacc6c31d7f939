"""Trajectory input for `lagbench fit` / `evaluate`: derivatives estimated from sampled positions.

A trajectory file (see `replication.fit.userdata`) holds rows of (traj, t, q[, qdot][, qddot][, tau]): one
or more trajectories, each sampled on its own uniform time grid. `with_derivatives(d, window,
polyorder)` returns the rows as state samples (q, qdot, qddot[, tau], traj, t), each trajectory sorted
by time. What the file gives is used as is; what it lacks is estimated, trajectory by trajectory:

  qdot   the first derivative of q;
  qddot  the first derivative of the given qdot, or else the second derivative of q.

The estimator is a Savitzky-Golay filter (`scipy.signal.savgol_filter`): at each sample, a polynomial of
degree `polyorder` is fitted by least squares to the `window` samples centred on it and differentiated
analytically there. The first and last window // 2 samples of a trajectory have no centred window (a
one-sided fit there is biased and several times noisier), so when any derivative is estimated they are
dropped: each trajectory keeps its samples window // 2 ... T - 1 - window // 2. Exact for polynomials of
degree <= polyorder; with white noise of standard deviation s on q at spacing h, the noise in the k-th derivative
scales as s / h^k / window^(k + 1/2): a wider window averages more noise away, but biases the estimate
where q curves on the window's time scale (window * h well below the motion's shortest period).
Checked against analytic trajectories with noise in tests/replication/fit/test_fit_trajectories.py.

Requirements (a ValueError naming the problem otherwise): an odd window >= polyorder + 2 >= 3 (so
that the second derivative exists and the fit is overdetermined), at least window + 1 samples per
trajectory (two are left after the ends are dropped), strictly increasing times within a trajectory, and a uniform spacing (relative spread
below 1e-6; resample a non-uniform recording first).
"""
from __future__ import annotations

import numpy as np

WINDOW = 15
POLYORDER = 3
UNIFORM_RTOL = 1e-6


def check_options(window, polyorder) -> None:
    ok_int = all(isinstance(v, int) and not isinstance(v, bool) for v in (window, polyorder))
    if not ok_int or polyorder < 2 or window % 2 == 0 or window < polyorder + 2:
        raise ValueError(f"--window {window!r} / --polyorder {polyorder!r}: not valid; expected an odd window >= "
                         f"polyorder + 2 and a polyorder >= 2 (defaults {WINDOW} and {POLYORDER})")


def derivative(x, h: float, order: int, window: int = WINDOW, polyorder: int = POLYORDER):
    """The `order`-th time derivative of samples x (T, d) at uniform spacing h, by Savitzky-Golay."""
    from scipy.signal import savgol_filter

    return savgol_filter(np.asarray(x, np.float64), window, polyorder, deriv=order, delta=h, axis=0,
                         mode="interp")


def spacing(t, where: str) -> float:
    """The uniform step of the times t (T,); a ValueError naming `where` if they are not uniform."""
    dt = np.diff(t)
    if not np.all(dt > 0):
        raise ValueError(f"{where}: times are not strictly increasing")
    h = float(np.mean(dt))
    if np.max(np.abs(dt - h)) > UNIFORM_RTOL * h:
        raise ValueError(f"{where}: times are not uniformly spaced (steps from {dt.min():.6g} to {dt.max():.6g}); "
                         f"resample the trajectory onto a uniform grid first")
    return h


def with_derivatives(d: dict, path: str, window: int = WINDOW, polyorder: int = POLYORDER) -> dict:
    """State samples (q, qdot, qddot[, tau], traj, t) from a trajectory file's arrays `d` (see module doc)."""
    check_options(window, polyorder)
    traj = d.get("traj", np.zeros(len(d["q"])))
    parts = []
    for k in np.unique(traj):
        rows = np.flatnonzero(traj == k)
        rows = rows[np.argsort(d["t"][rows], kind="stable")]
        where = f"{path}: trajectory {k:g}"
        estimate = "qdot" not in d or "qddot" not in d
        if estimate and rows.size < window + 1:
            raise ValueError(f"{where} has {rows.size} samples; estimating its derivatives needs at least "
                             f"{window + 1} (--window {window}, whose first and last {window // 2} are dropped)")
        t = d["t"][rows]
        h = spacing(t, where)
        part = {"traj": np.full(rows.size, float(k)), "t": t, "q": d["q"][rows]}
        part["qdot"] = d["qdot"][rows] if "qdot" in d else derivative(part["q"], h, 1, window, polyorder)
        if "qddot" in d:
            part["qddot"] = d["qddot"][rows]
        elif "qdot" in d:
            part["qddot"] = derivative(part["qdot"], h, 1, window, polyorder)
        else:
            part["qddot"] = derivative(part["q"], h, 2, window, polyorder)
        if "tau" in d:
            part["tau"] = d["tau"][rows]
        if estimate:  # no centred window at the ends
            part = {key: v[window // 2: rows.size - window // 2] for key, v in part.items()}
        parts.append(part)
    return {k: np.concatenate([p[k] for p in parts]) for k in parts[0]}


def starts(traj) -> list[np.ndarray]:
    """The row indices of each trajectory of `traj` (N,), in order of first appearance."""
    traj = np.asarray(traj)
    _, first = np.unique(traj, return_index=True)
    return [np.flatnonzero(traj == traj[i]) for i in np.sort(first)]
