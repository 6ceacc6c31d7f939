"""How tightly a recording pins the friction given the exact conservative double pendulum: `identification.py`'s
L1 and least-squares readings over 40 bootstrap resamples of the training file's trajectories (seeded).

    python docs/lab/recording_defaults/identification_spread.py FILE.csv [FILE.csv ...]
"""
import sys
from pathlib import Path

import numpy as np

from lagbench import systems
from lagbench.files import user_data
from lagbench.replication.fit import trajectories

sys.path.insert(0, str(Path(__file__).parent))
from identification import oracle  # noqa: E402

RESAMPLES = 40


def spread(exact, rows, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """(L1 readings, least-squares readings), one row per resample of whole trajectories."""
    traj = np.asarray(rows["traj"])
    ids = np.unique(traj)
    groups = {i: np.flatnonzero(traj == i) for i in ids}
    rng = np.random.default_rng(seed)
    l1s, lss = [], []
    for _ in range(RESAMPLES):
        pick = np.concatenate([groups[i] for i in rng.choice(ids, len(ids))])
        l1, ls, _rms = oracle(exact, {k: np.asarray(rows[k])[pick] for k in ("q", "qdot", "qddot")})
        l1s.append(l1)
        lss.append(ls)
    return np.array(l1s), np.array(lss)


def main(paths: list[str]) -> None:
    exact = systems.registry.get("double_pendulum", friction=0.0)
    for path in paths:
        _, d = user_data.read(path)
        l1s, lss = spread(exact, trajectories.with_derivatives(d, path, "auto", 3, gaps="split"))
        print(f"{path}: {RESAMPLES} resamples of its trajectories: L1 mean {l1s.mean(0).round(3)} sd "
              f"{l1s.std(0).round(3)}; least squares mean {lss.mean(0).round(3)} sd {lss.std(0).round(3)}")


if __name__ == "__main__":
    main(sys.argv[1:])
