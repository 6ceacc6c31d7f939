"""The friction a fit's training rows support, by estimator: with the true conservative double pendulum or with
the fitted model's own conservative part (its Rayleigh coefficients set to 0), the diagonal friction that best
explains the rows' estimated q-double-dot by L1 (the fit's loss) and by least squares; the model's own damping
in the system's units (K: its odd acceleration through the true mass matrix, fitted as -K qdot); and how much
of the conservative part's error lies along the friction's directions (least squares); L1 again against the
exact dynamics at the rows' states as targets, and how the model's conservative error correlates with the
filter's error (whether the fit learned the derivative filter's bias). On 20 000 training rows drawn with a
fixed seed.

    python docs/lab/recording_defaults/friction_estimators.py OUT/s0-delan     (a run.sh-style fit folder)
"""
import glob
import sys

import numpy as np
from scipy.optimize import minimize

from lagbench import systems
from lagbench.files import user_data
from lagbench.replication.fit.dissipation import softplus, with_coefficients
from lagbench.replication.fit.load import load_fitted

TRUE_FRICTION = 0.2   # the recordings' (run.sh)


def main(folder: str) -> None:
    f = load_fitted(glob.glob(folder + "/units/fit/jax/*/seed0")[0])
    r = user_data.rows(glob.glob(folder + "/data/train-fit-*.csv")[0], "train")
    n = min(20000, len(r["q"]))
    idx = np.random.default_rng(0).choice(len(r["q"]), n, replace=False)
    q, qd, qdd = (np.asarray(r[k], np.float64)[idx] for k in ("q", "qdot", "qddot"))
    exact = systems.registry.get("double_pendulum", friction=0.0)
    m = np.asarray(exact.mass_matrix(q))
    m_inv = np.linalg.inv(m)
    even_true = np.asarray(exact.acceleration(q, qd))
    b = softplus(np.asarray(f.params["dissipation.raw"]))
    q32, qd32 = q.astype(np.float32), qd.astype(np.float32)
    even_model = np.asarray(with_coefficients(f, np.zeros_like(b)).acceleration(q32, qd32), np.float64)
    odd = np.asarray(f.acceleration(q32, qd32), np.float64) - even_model
    k = -np.linalg.lstsq(qd, np.einsum("nij,nj->ni", m, odd), rcond=None)[0].T
    # the friction's directions in q-double-dot: column j is -M^-1 e_j qdot_j
    a = np.stack([-np.einsum("nij,nj->ni", m_inv, qd * e) for e in np.eye(2)], -1).reshape(-1, 2)

    def l1(even, target=qdd):
        res = target - even
        return minimize(lambda bb: np.abs(res + np.einsum("nij,nj->ni", m_inv, bb * qd)).sum(), x0=[0.2, 0.2],
                        method="Nelder-Mead").x

    def ls(even):
        return np.linalg.lstsq(a, (qdd - even).reshape(-1), rcond=None)[0]

    err = even_model - even_true
    # the exact dynamics at the rows' states (the recording's friction) as targets: what the filter's error moves
    clean = even_true - np.einsum("nij,nj->ni", m_inv, TRUE_FRICTION * qd)
    print(f"model's damping K diagonal: {np.diag(k).round(4)}")
    print(f"L1 friction against the exact dynamics as targets: true conservative part {l1(even_true, clean).round(4)}, "
          f"the model's {l1(even_model, clean).round(4)}")
    print(f"the filter's error (rms {np.sqrt(((qdd - clean) ** 2).mean()):.3g}) and the model's conservative error: "
          f"correlation {np.corrcoef(err.ravel(), (qdd - clean).ravel())[0, 1]:.3f}")
    print(f"L1 friction: true conservative part {l1(even_true).round(4)}, the model's {l1(even_model).round(4)}")
    print(f"least-squares friction: true conservative part {ls(even_true).round(4)}, the model's {ls(even_model).round(4)}")
    print(f"the model's conservative error along the friction's directions {np.linalg.lstsq(a, err.reshape(-1), rcond=None)[0].round(4)}"
          f" (its rms {np.sqrt((err ** 2).mean()):.3g})")


if __name__ == "__main__":
    main(sys.argv[1])
