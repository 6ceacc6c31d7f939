"""Shared by the loss-target fit tests (`test_fit_trajectory_loss.py`, `test_fit_filter_loss.py`): data files a
loss refuses."""
import numpy as np
import pandas as pd


def edited(recording, path, **columns):
    """A copy of the CSV `recording` at `path` with `columns` set (added where new) to the values given."""
    df = pd.read_csv(recording)
    for name, value in columns.items():
        df[name] = value
    df.to_csv(path, index=False)
    return path


def states(path):
    """A file of 40 pendulum state samples, no trajectory: q, qdot and the true qddot."""
    rng = np.random.default_rng(0)
    q, qdot = rng.normal(size=(40, 1)), rng.normal(size=(40, 1))
    np.savez(path, q=q, qdot=qdot, qddot=-9.81 * np.sin(q))
    return path
