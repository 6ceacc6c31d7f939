"""The velocity-odd part of a fitted dissipative LNN's dynamics on a file's states, in the system's units: the
generalized force F = M(q) (qddot(q, qdot) - qddot(q, -qdot)) / 2 (M the true double pendulum's mass matrix),
fitted as -K qdot with K a 2 x 2 matrix by least squares. The true system's odd part is exactly -0.2 I qdot: a
model whose F is far from linear in qdot (the residual's share of F) has odd forces besides its friction.

    python docs/lab/recording_defaults/odd_force.py OUT/s0-lnn_1x [N]
"""
import sys

import numpy as np

from lagbench import systems
from lagbench.files import user_data
from lagbench.replication.fit.load import load_fitted


def odd_force(folder: str, n: int = 3000) -> dict:
    f = load_fitted(folder)
    rows = user_data.rows(f.result["eval_config"]["test"], "test")
    q, qd = (np.asarray(rows[k][:n], np.float64) for k in ("q", "qdot"))
    m = systems.registry.get("double_pendulum").mass_matrix(q)
    a = [np.asarray(f.acceleration(q.astype(np.float32), (s * qd).astype(np.float32)), np.float64) for s in (1, -1)]
    force = np.einsum("nij,nj->ni", m, (a[0] - a[1]) / 2)
    k = -np.linalg.lstsq(qd, force, rcond=None)[0].T
    residual = np.linalg.norm(force + qd @ k.T) / np.linalg.norm(force)
    return {"K_diag": np.diag(k).round(4).tolist(), "K_antisym": round(float(k[0, 1] - k[1, 0]) / 2, 4),
            "nonlinear_share": round(float(residual), 3)}


if __name__ == "__main__":
    print(odd_force(sys.argv[1], *(int(x) for x in sys.argv[2:])))
