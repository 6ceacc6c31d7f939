"""Whether a fit learned the derivative filter's bias: the friction L1 reads given the exact or the model's
conservative part, against targets that are the exact dynamics at the training rows' states (friction 0.2) and
against the filter's estimate; and how the model's conservative error correlates with the filter's error.
20 000 training rows drawn with a fixed seed.

    python docs/lab/recording_defaults/filter_bias.py OUT/s0-lnn      (a run.sh-style fit folder)
"""
import glob
import sys

import numpy as np
from scipy.optimize import minimize

from lagbench import systems
from lagbench.files import user_data
from lagbench.replication.fit.dissipation import softplus, with_coefficients
from lagbench.replication.fit.load import load_fitted

TRUE_FRICTION = 0.2


def main(folder: str) -> None:
    f = load_fitted(glob.glob(folder + "/units/fit/jax/*/seed0")[0])
    r = user_data.rows(glob.glob(folder + "/data/train-fit-*.csv")[0], "train")
    n = min(20000, len(r["q"]))
    idx = np.random.default_rng(0).choice(len(r["q"]), n, replace=False)
    q, qd, qdd = (np.asarray(r[k], np.float64)[idx] for k in ("q", "qdot", "qddot"))
    exact = systems.registry.get("double_pendulum", friction=0.0)
    m_inv = np.linalg.inv(np.asarray(exact.mass_matrix(q)))
    even_true = np.asarray(exact.acceleration(q, qd))

    def friction(b):
        return -np.einsum("nij,nj->ni", m_inv, b * qd)

    clean = even_true + friction(np.full(2, TRUE_FRICTION))   # the exact dynamics at the rows' states
    b = softplus(np.asarray(f.params["dissipation.raw"]))
    even_model = np.asarray(with_coefficients(f, np.zeros_like(b)).acceleration(q.astype(np.float32),
                                                                                 qd.astype(np.float32)), np.float64)

    def l1(target, even):
        res = target - even
        return minimize(lambda bb: np.abs(res - friction(bb)).sum(), x0=[0.2, 0.2], method="Nelder-Mead",
                        options={"xatol": 1e-4}).x

    def ls(target, even):
        a = np.stack([friction(e) for e in np.eye(2)], -1).reshape(-1, 2)
        return np.linalg.lstsq(a, (target - even).reshape(-1), rcond=None)[0]

    for name, target in (("the exact dynamics at the rows' states", clean), ("the filter's estimate", qdd)):
        print(f"targets {name}: L1 with the exact conservative part {l1(target, even_true).round(3)}, with the "
              f"model's {l1(target, even_model).round(3)}; least squares with the model's {ls(target, even_model).round(3)}")
    bias, err = qdd - clean, even_model - even_true
    print(f"rms: the filter's error {np.sqrt((bias ** 2).mean()):.2f}, the model's conservative error "
          f"{np.sqrt((err ** 2).mean()):.2f}; their correlation {np.corrcoef(err.ravel(), bias.ravel())[0, 1]:.3f}")


if __name__ == "__main__":
    main(sys.argv[1])
