"""Pilot (not registered; no model trained): where in velocity a fitted LNN applies its friction. On a sample of
a set's rows, per angle and per quantile bin of |q-dot| of that angle: the local scale of the learned velocity
Hessian (median of H_jj / M_jj, M the system's mass matrix) and the damping the model applies, -F_j / q-dot_j
with F = M a_f and a_f = -H^-1 b q-dot its friction acceleration (least squares over the bin; true 0.2); then
the scale c of H against M and the residual |H - c M| / |H| per bin of the speed |q-dot|.

    python docs/lab/recording_defaults/damping_by_speed.py OUT/s0-lnn [val-test|train-fit] [ROWS]
"""
import glob
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from model_friction import EXACT  # noqa: E402

from lagbench.files import user_data  # noqa: E402
from lagbench.replication.fit.dissipation import softplus  # noqa: E402
from lagbench.replication.fit.load import load_fitted  # noqa: E402

QUANTILES = (0, 0.25, 0.5, 0.75, 0.9, 1)


def main(folder: str, which: str = "val-test", rows: int = 3000) -> None:
    f = load_fitted(glob.glob(folder + "/units/fit/jax/*/seed*")[0])
    data = user_data.rows(glob.glob(f"{folder}/data/{which}-*.csv")[0], "train" if which.startswith("train") else "test")
    q, qd = (np.asarray(data[k], np.float64) for k in ("q", "qdot"))
    pick = np.random.default_rng(0).choice(len(q), min(len(q), rows), replace=False)
    q, qd = q[pick], qd[pick]
    m = np.asarray(EXACT.mass_matrix(q))
    f.energy(q[:2], qd[:2])   # builds the float64 model the velocity Hessian is read from
    h = np.asarray(f.model.velocity_hessian(q, qd), np.float64)
    c = float(np.sum(h * m) / np.sum(m * m))
    b = softplus(np.asarray(f.params["dissipation.raw"], np.float64))
    force = np.einsum("nij,nj->ni", m, -np.einsum("nij,nj->ni", np.linalg.inv(h), b * qd))
    print(f"{folder} ({which}, {len(q)} rows): c {c:.3f}, b / |c| {np.round(b / abs(c), 3).tolist()}")
    for j in range(q.shape[1]):
        s = np.abs(qd[:, j])
        edges = np.quantile(s, QUANTILES)
        print(f"angle {j + 1}: |qdot| bin, local scale H_jj / M_jj (median), damping applied (least squares)")
        for lo, hi in zip(edges[:-1], edges[1:], strict=True):
            k = (s >= lo) & (s <= hi)
            damping = -np.sum(force[k, j] * qd[k, j]) / np.sum(qd[k, j] ** 2)
            print(f"  {lo:6.2f}-{hi:6.2f} rad/s: {np.median(h[k, j, j] / m[k, j, j]):.3f}, {damping:.3f} ({k.sum()} rows)")
    speed = np.linalg.norm(qd, axis=1)
    edges = np.quantile(speed, QUANTILES)
    print("|qdot| bin: scale c of H against M, residual")
    for lo, hi in zip(edges[:-1], edges[1:], strict=True):
        k = (speed >= lo) & (speed <= hi)
        ck = float(np.sum(h[k] * m[k]) / np.sum(m[k] ** 2))
        print(f"  {lo:6.2f}-{hi:6.2f}: {ck:.3f}, {np.linalg.norm(h[k] - ck * m[k]) / np.linalg.norm(h[k]):.3f}")


if __name__ == "__main__":
    main(sys.argv[1], *(sys.argv[2:3] or []), *(int(a) for a in sys.argv[3:4]))
