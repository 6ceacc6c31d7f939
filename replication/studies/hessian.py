"""Where the paper's formulation and the fast one part ways: a freshly initialised LNN's velocity Hessians.

`python -m lagbench.replication.studies.hessian [N]` (or `hessian_study(n, hidden, seed)` -> DataFrame): for N
double-pendulum training states and a fresh 3x600 LNN (the empirical init) with softplus and with ReLU,
in float32 and float64, one row each: the indefinite and singular fractions of d2L/dqdot2 (singular: the
smallest |eigenvalue| at or below pinv's relative cutoff), the fast solve's fallbacks, the relative
difference between the `fast` and `paper` accelerations (median, max, share above 1 %), the largest
condition number and the largest |qddot| each formulation predicts.
"""
from __future__ import annotations

import sys

import numpy as np
import pandas as pd

from lagbench import systems
from lagbench.models import ModelSpec, init_params
from lagbench.models.numerics import pinv_rtol


def hessian_study(n: int = 2000, hidden=(600, 600, 600), seed: int = 0) -> pd.DataFrame:
    import jax.numpy as jnp

    import lagbench.models.jax

    st = systems.get("double_pendulum").sample_states(n, np.random.default_rng(seed))
    rows = []
    for act in ("softplus", "relu"):
        for dt in ("float32", "float64"):
            q, qd = jnp.asarray(st["q"], dt), jnp.asarray(st["qdot"], dt)
            out = {}
            for form in ("fast", "paper"):
                spec = ModelSpec(kind="lnn", dof=2, hidden=tuple(hidden), dtype=dt, angle_wrap=True,
                                 formulation=form, activation=act)
                m = lagbench.models.jax.build(spec, init_params(spec, seed=seed))
                qdd, n_fb = m.acceleration_info(q, qd)
                out[form] = (np.asarray(qdd, np.float64), int(n_fb))
            eig = np.linalg.eigvalsh(np.asarray(m.velocity_hessian(q, qd), np.float64))
            a = np.abs(eig)
            f, p = out["fast"][0], out["paper"][0]
            rel = np.linalg.norm(f - p, axis=-1) / np.maximum(np.linalg.norm(p, axis=-1), 1e-300)
            rows.append({"activation": act, "dtype": dt, "n_states": n,
                         "indefinite_fraction": float(np.mean((eig[:, 0] < 0) & (eig[:, -1] > 0))),
                         "singular_fraction": float(np.mean(a.min(-1) <= pinv_rtol(dt, 2) * a.max(-1))),
                         "fast_fallbacks": out["fast"][1],
                         "fast_vs_paper_median": float(np.median(rel)), "fast_vs_paper_max": float(rel.max()),
                         "fast_vs_paper_above_1pct": float(np.mean(rel > 0.01)),
                         "cond_max": float(np.max(np.where(a.min(-1) > 0, a.max(-1) / np.where(
                             a.min(-1) > 0, a.min(-1), 1.0), np.inf))),
                         "qddot_max_fast": float(np.abs(f).max()), "qddot_max_paper": float(np.abs(p).max())})
    return pd.DataFrame(rows)


if __name__ == "__main__":
    print(hessian_study(int(sys.argv[1]) if len(sys.argv) > 1 else 2000).to_string(index=False))
