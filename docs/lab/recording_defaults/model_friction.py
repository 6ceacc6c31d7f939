"""A fit's friction read as b / c, with c the least-squares factor of its mass matrix (DeLaN) or velocity Hessian
(LNN) against the true one, at the development test file's first 4 000 rows; beside it that matrix's relative
residual and the fit's q-double-dot error against the exact dynamics (friction 0.2) there, as a fraction of the
exact q-double-dot's rms (the pilot's readings, `filtered_loss_pilot.py`, for fitted folders). DeLaN's fit
records no friction reading of its own; this gives the study's rule (a) one for DeLaN and the LNN alike.

    python docs/lab/recording_defaults/model_friction.py OUT/s0-delan OUT/s0-delan_filtered ...
"""
import glob
import sys

import numpy as np

from lagbench import systems
from lagbench.files import user_data
from lagbench.replication.fit.dissipation import softplus
from lagbench.replication.fit.load import load_fitted

EXACT = systems.registry.get("double_pendulum", friction=0.0)
TRUE_FRICTION = 0.2


def reading(folder: str) -> dict:
    f = load_fitted(glob.glob(folder + "/units/fit/jax/*/seed*")[0])
    test = user_data.rows(glob.glob(folder + "/data/val-test-*.csv")[0], "test")
    q, qd = (np.asarray(test[k], np.float64)[:4000] for k in ("q", "qdot"))
    m_true = np.asarray(EXACT.mass_matrix(q))
    f.energy(q[:2], qd[:2])   # builds the float64 model (`_model64`) the mass matrix is read from
    m = (np.asarray(f.model.velocity_hessian(q, qd), np.float64) if f.spec.kind == "lnn" else
         np.asarray(f._model64.mass_matrix(q), np.float64))
    c = float(np.sum(m * m_true) / np.sum(m_true * m_true))
    b = softplus(np.asarray(f.params["dissipation.raw"], np.float64))
    exact = np.asarray(EXACT.acceleration(q, qd)) - np.einsum("nij,nj->ni", np.linalg.inv(m_true), TRUE_FRICTION * qd)
    pred = np.asarray(f.acceleration(q, qd), np.float64)
    return {"friction b / c": (b / c).round(4).tolist(),
            "matrix residual": round(float(np.linalg.norm(m - c * m_true) / np.linalg.norm(m)), 4),
            "error vs exact": round(float(np.sqrt(((pred - exact) ** 2).mean() / (exact ** 2).mean())), 4)}


if __name__ == "__main__":
    for folder in sys.argv[1:]:
        print(folder, reading(folder), flush=True)
