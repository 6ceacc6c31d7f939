"""How well a recording identifies the friction at all: given the true conservative double pendulum, the diagonal
friction that best explains the estimated q-double-dot of every training row, by L1 (the fit's loss) and by least
squares; at the fit's auto derivative window, or with --windows at each of a list of windows and degrees 3 and 5.
No model is trained. Gaps are split (`--gaps split`), so that a file with a run of dropped frames longer than the
fit interpolates is read too.

    python docs/lab/recording_defaults/identification.py FILE.csv [FILE.csv ...]
    python docs/lab/recording_defaults/identification.py --windows FILE.csv
"""
import sys

import numpy as np
from scipy.optimize import minimize

from lagbench import systems
from lagbench.files import user_data
from lagbench.replication.fit import trajectories

WINDOWS = (7, 9, 11, 13, 15, 19, 23, 27, 31)


def oracle(exact, r) -> tuple[np.ndarray, np.ndarray, float]:
    """(L1 friction, least-squares friction, rms of the rows' q-double-dot residual under the exact dynamics)."""
    q, qd, qdd = (np.asarray(r[k], np.float64) for k in ("q", "qdot", "qddot"))
    m_inv = np.linalg.inv(np.asarray(exact.mass_matrix(q)))
    res = qdd - np.asarray(exact.acceleration(q, qd))
    a = np.stack([-np.einsum("nij,nj->ni", m_inv, qd * e) for e in np.eye(2)], -1).reshape(-1, 2)
    ls = np.linalg.lstsq(a, res.reshape(-1), rcond=None)[0]
    l1 = minimize(lambda bb: np.abs(res + np.einsum("nij,nj->ni", m_inv, bb * qd)).sum(), x0=[0.2, 0.2],
                  method="Nelder-Mead", options={"xatol": 1e-4}).x
    return l1, ls, float(np.sqrt((res ** 2).mean()))


def main(args: list[str]) -> None:
    every = "--windows" in args
    exact = systems.registry.get("double_pendulum", friction=0.0)
    for path in [a for a in args if a != "--windows"]:
        _, d = user_data.read(path)
        choices = [(w, p) for p in (3, 5) for w in WINDOWS if w >= p + 2] if every else [("auto", 3)]
        for w, p in choices:
            l1, ls, rms = oracle(exact, trajectories.with_derivatives(d, path, w, p, gaps="split"))
            print(f"{path} window {w} degree {p}: L1 {l1.round(3)}  least squares {ls.round(3)}  "
                  f"(residual rms {rms:.3g})", flush=True)


if __name__ == "__main__":
    main(sys.argv[1:])
