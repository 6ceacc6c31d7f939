"""Pilot (not registered; no model trained): how one-sided a recording's velocities are. The angles wrapped and
cut into an 8 x 8 grid of cells; per angle, over the rows with |q-dot_j| at least a quantile of it, the
q-dot_j^2-weighted share of each cell's motion that runs one way, |sum w sign(q-dot_j)| / sum w, summed over
the cells. 0: every cell sees the angle turn both ways alike; 1: each cell one way only. Where a cell sees one
direction, a term even in q-dot (as a Lagrangian's) can stand in for the friction, which is odd.

    python docs/lab/recording_defaults/velocity_sides.py OUT/s0-lnn/data/train-fit-*.csv   (a fit's file: it has q-dot)
"""
import sys

import numpy as np

from lagbench.files import user_data

CELLS = 8


def main(path: str) -> None:
    d = user_data.rows(path, "test" if "/val-" in path else "train")
    q, qd = (np.asarray(d[k], np.float64) for k in ("q", "qdot"))
    wrapped = np.mod(q + np.pi, 2 * np.pi) - np.pi
    index = np.clip(((wrapped + np.pi) / (2 * np.pi) * CELLS).astype(int), 0, CELLS - 1)
    cell = index[:, 0] * CELLS + index[:, 1]
    for j in range(q.shape[1]):
        for quantile in (0, 0.5, 0.9):
            lo = np.quantile(np.abs(qd[:, j]), quantile)
            keep = np.abs(qd[:, j]) >= lo
            w, sign, cells = qd[keep, j] ** 2, np.sign(qd[keep, j]), cell[keep]
            one_way = sum(abs(np.sum(w[cells == c] * sign[cells == c])) for c in np.unique(cells))
            print(f"angle {j + 1}, |qdot| >= {lo:5.2f} (rows {keep.sum()}): one-sided share {one_way / w.sum():.3f}")


if __name__ == "__main__":
    main(sys.argv[1])
