"""A set's trajectories rolled out together: `by_time_grid(r, horizon=None)` groups the trajectories of the
rows `r` by their time grid (from 0; to `horizon` seconds when given), {grid: [row indices]}, so that the
trajectories of one grid roll out as one batch; `mean_state_error(f, r, horizon, substeps)` is the fitted
model's rollout error as `evaluate` reports it (S_rollout_gmean_err: `metrics.bounded_relative_error` of
(q, qdot) against the data per time, its geometric mean over time, averaged over the trajectories), for the
checks that roll a variant of a fit out (`replication.fit.dissipation`)."""
from __future__ import annotations

import numpy as np

from lagbench.replication.evaluation.metrics import bounded_relative_error, geometric_mean_over_time
from lagbench.replication.fit.trajectories import starts


def by_time_grid(r, horizon=None) -> dict:
    groups: dict = {}
    for idx in starts(r["traj"]):
        t = r["t"][idx] - r["t"][idx[0]]
        if horizon is not None:
            keep = t <= horizon * (1 + 1e-12)
            if keep.sum() < 2:
                raise ValueError(f"--horizon {horizon}: shorter than the first sample interval ({t[1]:.6g} s) of "
                                 f"trajectory {r['traj'][idx[0]]}")
            idx, t = idx[keep], t[keep]
        groups.setdefault(tuple(np.round(t, 9)), []).append(idx)
    return groups


def mean_state_error(f, r, horizon=None, substeps=2) -> float:
    """S_rollout_gmean_err of the fitted model `f` (a forward model without torques) on the rows `r`."""
    errs = []
    for grid, members in by_time_grid(r, horizon).items():
        t = np.asarray(grid)
        z_data = np.stack([np.concatenate([r["q"][i], r["qdot"][i]], 1) for i in members])
        z = f.rollout(z_data[:, 0], t, (t[1] - t[0]) / substeps)
        errs.append(geometric_mean_over_time(bounded_relative_error(z, z_data)))
    return float(np.mean(np.concatenate(errs)))
