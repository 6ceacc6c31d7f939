"""Friction from the energy balance on a fit's recorded training trajectories, dE/dt = -sum_j b_j qdot_j^2 (no
q-double-dot): with E the true energy, and with the fitted model's own energy divided by its scale c against the
true mass matrix (as the fit reads b / |c|); qdot as the fit estimated it; the trajectories cut into pieces of
SPAN frames (none across a gap), least squares over the pieces.

    python docs/lab/recording_defaults/energy_balance.py OUT/s0-lnn      (a run.sh-style fit folder)
"""
import glob
import sys

import numpy as np

from lagbench import systems
from lagbench.files import user_data
from lagbench.replication.fit.dissipation import softplus
from lagbench.replication.fit.load import load_fitted

SPANS = (5, 10, 30, 100)


def main(folder: str) -> None:
    f = load_fitted(glob.glob(folder + "/units/fit/jax/*/seed0")[0])
    r = user_data.rows(glob.glob(folder + "/data/train-fit-*.csv")[0], "train")
    q, qd, traj, t = (np.asarray(r[k], np.float64) for k in ("q", "qdot", "traj", "t"))
    exact = systems.registry.get("double_pendulum", friction=0.0)
    e_true, e_model = np.asarray(exact.energy(q, qd)), np.asarray(f.energy(q, qd), np.float64)
    keep = slice(0, 2000)
    h = (np.asarray(f.model.velocity_hessian(q[keep], qd[keep]), np.float64) if f.spec.kind == "lnn" else
         np.asarray(f._model64.mass_matrix(q[keep]), np.float64))
    m = np.asarray(exact.mass_matrix(q[keep]))
    c = float(np.sum(h * m) / np.sum(m * m))
    print(f"the fit's b / |c|: {(softplus(np.asarray(f.params['dissipation.raw'])) / abs(c)).round(4)} (c {c:.4g})")
    for span in SPANS:
        a, yt, ym = [], [], []
        for k in np.unique(traj):
            s = np.flatnonzero(traj == k)
            for a0 in range(0, len(s) - 2, span):
                sl = s[a0:a0 + span + 1]
                if len(sl) < 3 or np.ptp(np.diff(t[sl])) > 1e-6:
                    continue
                a.append(-np.trapezoid(qd[sl] ** 2, t[sl], axis=0))
                yt.append(e_true[sl[-1]] - e_true[sl[0]])
                ym.append(e_model[sl[-1]] - e_model[sl[0]])
        a = np.array(a)
        bt = np.linalg.lstsq(a, np.array(yt), rcond=None)[0]
        bm = np.linalg.lstsq(a, np.array(ym), rcond=None)[0] / c   # c < 0: the model's energy is -|c| E
        print(f"pieces of {span:3d} frames ({len(yt)}): true energy {bt.round(4)}; the model's energy / c {bm.round(4)}")


if __name__ == "__main__":
    main(sys.argv[1])
