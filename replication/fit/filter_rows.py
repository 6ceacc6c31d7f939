"""Rows of a recording with their neighbouring frames, the training rows of the filtered acceleration loss
(`Protocol.filter_loss`, `lagbench fit --loss-target filtered`).

`neighbours(r, taps) -> (rows, at)`: of rows `r` of a prepared trajectory file (`user_data.rows`: traj, t, q,
qdot, qddot, each trajectory on its uniform grid with the derivative filter's ends and any interpolated frame
already dropped), the rows whose `taps` frames centred on them (taps odd) are all rows of their trajectory, and
`at` (n, taps) those frames' rows in time order. A row next to a trajectory's end, a cut `--gaps split` makes
or an interpolated frame is left out: the model's q-double-dot is known only where (q, qdot) are.
`filter_rows(r, part) -> dict`: the batch dict of `replication.training.data` for those rows:
  q, qdot         (n, dof): the row's own (for what reads a row: nothing in the loss);
  q_taps, qdot_taps (n, taps*dof): its frames', frame after frame (what `objective.filtered` reads);
  target, qddot   (n, dof): the row's estimated q-double-dot.
`training_rows(ref, part)`: those of the training rows of the prepared file `ref`; a ValueError naming the
window where none has its frames whole.
`check_fit(path, task, recording, given)`: the filtered loss refused, in one line, where it has no second
derivative of q to follow (a file of state samples, or one that gives qdot or qddot: `given`) or no
q-double-dot to filter (an HNN's time derivatives, an inverse-dynamics fit).
"""
from __future__ import annotations

import numpy as np

from lagbench.files import user_data
from lagbench.replication.fit.windows import consecutive, runs


def neighbours(r: dict, taps: int) -> tuple[np.ndarray, np.ndarray]:
    half = taps // 2
    keep, at = [np.zeros(0, int)], [np.zeros((0, taps), int)]
    for rows, frame in runs(r):
        ok = consecutive(frame, taps - 1)
        keep.append(rows[ok + half])
        at.append(rows[ok[:, None] + np.arange(taps)])
    return np.concatenate(keep), np.concatenate(at)


def filter_rows(r: dict, part) -> dict:
    taps = len(part.kernel)
    keep, at = neighbours(r, taps)
    n, dof = keep.size, r["q"].shape[1]
    return {"q": r["q"][keep], "qdot": r["qdot"][keep], "q_taps": r["q"][at].reshape(n, taps * dof),
            "qdot_taps": r["qdot"][at].reshape(n, taps * dof), "target": r["qddot"][keep], "qddot": r["qddot"][keep]}


def training_rows(ref: str, part) -> dict:
    r = user_data.rows(ref, "train")
    if "t" not in r or "traj" not in r:
        raise ValueError(f"{ref}: the filtered loss needs a prepared trajectory file (traj, t, q, qdot columns)")
    out = filter_rows(r, part)
    if not len(out["q"]):
        raise ValueError(f"--loss-target filtered: no training row has the {len(part.kernel)} frames about it that "
                         f"the derivative filter's window {part.window} spans (after the filter dropped each "
                         f"trajectory's ends); give a smaller --window or longer trajectories")
    return out


def check_fit(path, task: str, recording: bool, given) -> None:
    if not recording:
        raise ValueError(f"--loss-target filtered: {path} is a file of state samples; the filtered loss follows the "
                         f"derivative filter along recorded trajectories (a file with t and q columns), or use "
                         f"--loss-target acceleration")
    if given:
        raise ValueError(f"--loss-target filtered: {path} gives {' and '.join(given)}, so its q-double-dot is not the "
                         f"filter's second derivative of q that the loss follows; use --loss-target acceleration")
    if task == "inverse_dynamics":
        raise ValueError(f"--loss-target filtered: {path} has tau columns, so the model learns the inverse dynamics "
                         f"tau(q, qdot, qddot), not q-double-dot; use --loss-target acceleration")
    if task != "acceleration":
        raise ValueError("--loss-target filtered: an HNN's loss reads its time derivatives (qdot and qddot), not "
                         "q-double-dot alone; use --loss-target acceleration")
