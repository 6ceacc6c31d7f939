"""`lagbench simulate`: noisy trajectories of a system of `systems/`, written as a trajectory file that
`lagbench fit` and `lagbench evaluate` read (docs/fit.md's worked example makes its data with it).

`simulate(system, trajectories, duration, rate, noise, seed, velocities=False) -> DataFrame` with columns
traj, t, q0..q{d-1} (and qdot0.. with `velocities`): each trajectory starts from a state drawn from the
system's own distribution (`System.sample_states`, generator seeded by `seed`) and is integrated in
float64 by diffrax at tight tolerances (`systems.trajectories.integrate`), sampled every 1 / rate
seconds from t = 0 to `duration`; independent Gaussian noise of standard deviation `noise` (in the
units of q, and of qdot) is then added to every sample. As a real recording: `dropped`, the share of
samples (never a trajectory's first or last) left out at random, as a logger that drops frames; `decimals`,
the times rounded to that many decimals when written. `settings`: "NAME=VALUE" system parameters or options
(`--set friction=0.2`: viscous friction). A ValueError names a bad option.
"""
from __future__ import annotations

import math

import numpy as np
import pandas as pd


def check_options(system, trajectories, duration, rate, noise, seed, dropped=0.0, decimals=None) -> None:
    from lagbench import systems

    if system not in systems.names():
        raise ValueError(f"--system: unknown {system!r}; valid: {', '.join(systems.names())}")
    real = [(n, v) for n, v in (("--duration", duration), ("--rate", rate), ("--noise", noise))
            if not (isinstance(v, (int, float)) and math.isfinite(v))]
    if real:
        raise ValueError(f"{real[0][0]}: {real[0][1]!r} is not a finite number")
    checks = [("--trajectories", isinstance(trajectories, int) and trajectories >= 1, "an integer >= 1", trajectories),
              ("--duration", duration > 0, "a number > 0 (seconds)", duration),
              ("--rate", rate > 0 and duration * rate >= 2, "a number > 0 with duration x rate >= 2 (samples per "
               "second)", rate),
              ("--noise", noise >= 0, "a number >= 0", noise),
              ("--seed", isinstance(seed, int) and seed >= 0, "an integer >= 0", seed),
              ("--dropped", isinstance(dropped, (int, float)) and 0 <= dropped < 0.5, "a share in [0, 0.5)", dropped),
              ("--decimals", decimals is None or (isinstance(decimals, int) and decimals >= 1), "an integer >= 1",
               decimals)]
    for option, ok, valid, value in checks:
        if not ok:
            raise ValueError(f"{option}: {value!r} is not valid; expected {valid}")


def parse_settings(settings) -> dict:
    """{name: float or int} from "NAME=VALUE" strings (`--set`); a ValueError names a malformed one."""
    out = {}
    for item in settings or ():
        name, sep, value = str(item).partition("=")
        try:
            number = float(value)
        except ValueError:
            number = None
        if not sep or not name.isidentifier() or number is None or not math.isfinite(number):
            raise ValueError(f"--set {item}: give NAME=VALUE with a finite number, e.g. friction=0.2")
        out[name] = int(number) if number.is_integer() and "." not in value and "e" not in value.lower() else number
    return out


def simulate(system="pendulum", trajectories=8, duration=5.0, rate=50.0, noise=0.0, seed=0,
             velocities=False, dropped=0.0, decimals=None, settings=()) -> pd.DataFrame:

    import lagbench.systems.trajectories
    from lagbench import systems

    check_options(system, trajectories, duration, rate, noise, seed, dropped, decimals)
    try:
        s = systems.get(system, **parse_settings(settings))
    except (TypeError, KeyError) as e:
        raise ValueError(f"--set: {e}") from None
    rng = np.random.default_rng(seed)
    st = s.sample_states(trajectories, rng)
    t = np.arange(int(math.floor(duration * rate + 1e-9)) + 1) / rate
    q, qd = lagbench.systems.trajectories.integrate(s, st["q"], st["qdot"], t)
    q = q + noise * rng.standard_normal(q.shape)
    qd = qd + noise * rng.standard_normal(qd.shape)
    b, n, d = q.shape
    cols = {"traj": np.repeat(np.arange(b), n), "t": np.tile(t, b)}
    cols.update({f"q{j}": q[..., j].ravel() for j in range(d)})
    if velocities:
        cols.update({f"qdot{j}": qd[..., j].ravel() for j in range(d)})
    df = pd.DataFrame(cols)
    if decimals is not None:
        df["t"] = df["t"].round(decimals)
    if dropped:   # drawn after the noise: the kept rows are those of the recording without drops
        inner = (df["t"] > 0) & (np.tile(np.arange(n), b) < n - 1)
        df = df[~(inner & (np.random.default_rng([seed, 1]).random(len(df)) < dropped))].reset_index(drop=True)
    return df
