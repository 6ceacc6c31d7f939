"""Windows of a recording, the training rows of the trajectory loss (`Protocol.trajectory_loss`, `lagbench fit
--loss-target trajectory`).

`windows(r, part, loss) -> dict`: from rows `r` of a prepared trajectory file (`user_data.rows`: traj, t, q, qdot,
..., each trajectory on its uniform grid with the derivative filter's ends and any interpolated frame already
dropped: `replication.fit.trajectories`), one window per row whose trajectory holds the next `part.frames` = K
frames of its grid, each of them a row; by trajectory (in the rows' order), then by time. A batch dict of
`replication.training.data`:
  q, qdot  (B, dof): the start row's q (as recorded) and qdot (as estimated for the one-step loss);
  h        (B, 1): the window's frame step, (t_K - t_0) / K;
  scale    (B, 1): the factor `scale_of` gives the window;
  target   (B, K*dof): (q_k - q_0) x scale for k = 1..K, frame after frame (what
           `replication.training.objective.positions` predicts).
`window_rows(r, k)` gives each window's rows and `windows_of(r, at, part, loss)` the batch dict of any such
rows (a lab pilot reads windows backwards through it). A window never crosses a trajectory's end, a cut `--gaps split` makes (its pieces are trajectories of their own)
or an interpolated frame: `--gaps interpolate` fills dropped frames for the derivative filter only, and a window
that would hold a filled frame is not cut (its positions are made up).

`scale_of(h, frames, loss, scale)`: "acceleration": 1 / the loss of the displacements a constant q-double-dot
error e = 1 gives over a window (e (k h)^2 / 2 at frame k): 2 / (h^2 sum k^2) for L1, 2 / (h^2 sqrt(sum k^4)) for
the squared error, so that a model whose q-double-dot is off by a constant e has the loss the acceleration
loss gives it, |e| or e^2, in q-double-dot units (the kind's learning rate, L2 weight and guard keep their
meaning); "none": 1.
`training_windows(ref, part, loss)`: the windows of the training rows of the prepared file `ref` (the data
recipe's: `replication.training.data.recipe_file`); a ValueError naming `--horizon-frames` where there are none.
`check_fit(path, task, recording)`: the trajectory loss refused, in one line, for a file of state samples or a
fit of the inverse dynamics (no motion of the model's to integrate).
`runs(r)`: (rows in time order, frame on the trajectory's grid) of each trajectory of the rows `r`;
`consecutive(frame, k)`: the indices i where frames i .. i + k are k + 1 frames in a row of that grid.
`FRAMES`, `SUBSTEPS`: `lagbench fit`'s defaults.
"""
from __future__ import annotations

import numpy as np

from lagbench.files import user_data
from lagbench.replication.fit.trajectories import grid, starts

FRAMES = 5      # frames a window spans: 0.05 s at 100 frames/s, short beside a double pendulum's motion
SUBSTEPS = 2    # RK4 steps a frame, as the rollouts' default (`--substeps`)


def scale_of(h, frames: int, loss: str, scale: str):
    k = np.arange(1, frames + 1, dtype=np.float64)
    if scale == "none":
        return np.ones_like(h)
    spread = np.sqrt(np.sum(k ** 4)) if loss == "mse" else np.sum(k ** 2)
    return 2.0 / (h * h * spread)


def runs(r: dict) -> list[tuple[np.ndarray, np.ndarray]]:
    """(rows in time order, frame on the trajectory's grid) of each trajectory of the rows `r`."""
    out = []
    for rows in starts(r["traj"]):
        rows = rows[np.argsort(r["t"][rows], kind="stable")]
        _, frame = grid(r["t"][rows], "prepared rows", "split")
        out.append((rows, frame))
    return out


def consecutive(frame, k: int):
    # frames strictly increase, so k + 1 of them span exactly k steps only where none is missing; a run of at
    # most k frames holds no such span (and `frame[:size - k]` would wrap around)
    if frame.size <= k:
        return np.zeros(0, int)
    return np.flatnonzero(frame[k:] - frame[:frame.size - k] == k)


def window_rows(r: dict, k: int) -> np.ndarray:
    """(windows, k + 1): each window's rows, its start and the K frames after it."""
    at = [np.zeros((0, k + 1), int)]
    for rows, frame in runs(r):
        ok = consecutive(frame, k)
        at.append(rows[ok[:, None] + np.arange(k + 1)])
    return np.concatenate(at)


def windows(r: dict, part, loss: str) -> dict:
    return windows_of(r, window_rows(r, part.frames), part, loss)


def windows_of(r: dict, at: np.ndarray, part, loss: str) -> dict:
    """The batch dict of the windows whose rows `at` holds (`window_rows`), frame by frame from its first."""
    k = part.frames
    first, q, t = at[:, 0], r["q"], r["t"]
    h = ((t[at[:, -1]] - t[first]) / k)[:, None]
    scale = scale_of(h, k, loss, part.scale)
    target = ((q[at[:, 1:]] - q[first][:, None, :]) * scale[:, :, None]).reshape(first.size, k * q.shape[1])
    return {"q": q[first], "qdot": r["qdot"][first], "h": h, "scale": scale, "target": target}


def longest(r: dict) -> int:
    """The most rows in a row on one trajectory's grid (a window of K frames needs K + 1)."""
    best = 0
    for _, frame in runs(r):
        breaks = np.flatnonzero(np.diff(frame) != 1)
        bounds = np.concatenate([[0], breaks + 1, [frame.size]])
        best = max(best, int(np.max(np.diff(bounds))) if frame.size else 0)
    return best


def training_windows(ref: str, part, loss: str) -> dict:
    r = user_data.rows(ref, "train")
    if "t" not in r or "traj" not in r:
        raise ValueError(f"{ref}: the trajectory loss needs a prepared trajectory file (traj, t, q, qdot columns)")
    out = windows(r, part, loss)
    if not len(out["q"]):
        n = longest(r)
        raise ValueError(f"--horizon-frames {part.frames}: no training trajectory holds {part.frames + 1} frames in a "
                         f"row (the longest run has {n}, after the derivative filter dropped each trajectory's ends); "
                         f"give at most {max(n - 1, 1)}")
    return out


def check_fit(path, task: str, recording: bool) -> None:
    if not recording:
        raise ValueError(f"--loss-target trajectory: {path} is a file of state samples; the trajectory loss integrates "
                         f"the model over windows of recorded trajectories (a file with t and q columns), or use "
                         f"--loss-target acceleration")
    if task == "inverse_dynamics":
        raise ValueError(f"--loss-target trajectory: {path} has tau columns, so the model learns the inverse dynamics "
                         f"tau(q, qdot, qddot), which has no motion to integrate; use --loss-target acceleration")
