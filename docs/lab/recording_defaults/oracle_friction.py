"""The friction a recording identifies when the conservative dynamics are known: the diagonal friction b that
best explains a fit's prepared rows, q-double-dot estimated = f(q, q-dot) - M(q)^-1 diag(b) q-dot with f the true
frictionless double pendulum, by the L1 error on q-double-dot (the fit's loss), on the training rows.

    python docs/lab/recording_defaults/oracle_friction.py OUT/s0-lnn_1x/data/train-fit-*.csv ...
"""
import sys

import numpy as np
from scipy.optimize import minimize

from lagbench import systems
from lagbench.files import user_data


def oracle(path: str, split: str = "train") -> np.ndarray:
    r = user_data.rows(path, split)
    q, qd, qdd = (np.asarray(r[k], float) for k in ("q", "qdot", "qddot"))
    exact = systems.registry.get("double_pendulum", friction=0.0)
    residual = qdd - np.asarray(exact.acceleration(q, qd))
    m_inv = np.linalg.inv(np.asarray(exact.mass_matrix(q)))
    return minimize(lambda b: np.abs(residual + np.einsum("nij,nj->ni", m_inv, b * qd)).sum(), x0=[0.2, 0.2],
                    method="Nelder-Mead").x


if __name__ == "__main__":
    for path in sys.argv[1:]:
        print(f"{path}: b = {', '.join(f'{x:.3f}' for x in oracle(path))}")
