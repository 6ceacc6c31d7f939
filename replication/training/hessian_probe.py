"""Velocity-Hessian health during training, written once for both training loops.

At every logged step of an LNN or LGN trained on accelerations, `probe(model, batch, to_numpy)` looks at
the current batch through the model's own public methods (no gradient, not part of the update):
  hessian_fallbacks            samples whose `fast` solve was not finite and took the counted pinv
                               fallback (always 0 for `paper`, which is pinv everywhere)
  hessian_indefinite_fraction  share of samples whose d^2L/dqdot^2 has eigenvalues of both signs (the
                               Euler-Lagrange solve is still defined, the "kinetic energy" is not convex)
  hessian_singular_fraction    share whose smallest |eigenvalue| is at or below pinv's relative cutoff
                               (`models.numerics.pinv_rtol`): there `paper`'s pinv drops a direction and
                               the `fast` solve's answer is large; the two formulations differ
  qddot_max_abs                the largest |q-double-dot| the model predicts on the batch (a huge one
                               is visible here, never silent)
Eigenvalues need `velocity_hessian` (LNN); the LGN reports fallbacks and qddot_max_abs only.
`summarize(log)` reduces the logged rows to result counters (mean and max over logged steps, total).
"""
from __future__ import annotations

import numpy as np

from lagbench.models.numerics import pinv_rtol
from lagbench.models.spec import CAPABILITIES

KINDS = tuple(k for k, c in CAPABILITIES.items() if c.lagrangian_hessian)
COLUMNS = ("hessian_fallbacks", "hessian_indefinite_fraction", "hessian_singular_fraction", "qddot_max_abs")


def wanted(spec, protocol) -> bool:
    return spec.kind in KINDS and protocol.task == "acceleration"


def probe(qdd, n_fallback, hess, dtype: str) -> dict:
    """The logged columns from one batch: qdd (B, d), n_fallback (int), hess (B, d, d) or None (NumPy)."""
    row = {"hessian_fallbacks": int(n_fallback), "qddot_max_abs": float(np.max(np.abs(qdd)))}
    if hess is not None:
        eig = np.linalg.eigvalsh(np.asarray(hess, np.float64))
        a = np.abs(eig)
        row["hessian_indefinite_fraction"] = float(np.mean((eig[:, 0] < 0) & (eig[:, -1] > 0)))
        row["hessian_singular_fraction"] = float(np.mean(
            a.min(-1) <= pinv_rtol(dtype, eig.shape[-1]) * a.max(-1)))
    return row


def summarize(log: list) -> dict:
    """Result counters from the train log rows: train_<column>_mean / _max, train_hessian_fallbacks_total."""
    out = {}
    for col in COLUMNS:
        vals = np.array([r[col] for r in log if r.get(col) is not None and np.isfinite(r[col])], float)
        if not len(vals):
            continue
        if col == "hessian_fallbacks":
            out["train_hessian_fallbacks_total"] = int(vals.sum())
        out[f"train_{col}_mean"] = float(vals.mean())
        out[f"train_{col}_max"] = float(vals.max())
    return out
