"""The time base of a trajectory file: its unit (`--time-unit`) and a check against the system it records.

`TIME_UNITS`: "s" (seconds, the default) and "ms" (milliseconds); `in_seconds(d, unit)` returns a file's
arrays with the t column in seconds (t / 1000 for "ms"). `step(d)`: the median step between consecutive
samples of the file's trajectories, in the file's own unit (None without two samples in a trajectory).

`time_scale(system)`: the system's time scale in seconds, sqrt(rms(q - mean q) / rms(q̈)) over 256 states
of its own distribution (seed 0, unforced): 1 / omega for a harmonic oscillator, 0.1 s (stiff_chain) to
4 s (relativistic) over the suite's systems.

`check_unit(path, d, system, unit)`: a unit other than seconds for a file without a t column is refused (a
state file's qdot and qddot are per second); with a `system` (`--system`), so is a step longer than the system's time scale is refused
(a ValueError): fewer than one sample per time scale cannot resolve the motion, and a derivative window of
15 such samples spans several periods. That is what times in integer milliseconds read as seconds look
like (a 50 Hz recording: a step of 20 against pendulum's 0.74 s), so the error names the unit the step
looks like where one fits. A step far below the time scale is not refused: a fast recording is legitimate.
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np

TIME_UNITS = {"s": 1.0, "ms": 1e-3}   # unit -> seconds per unit
NAMES = {"s": "seconds", "ms": "milliseconds"}


def in_seconds(d: dict, unit: str) -> dict:
    """The arrays `d` with t in seconds (a new dict; `d` is a cached parse and stays as read)."""
    if unit == "s" or "t" not in d:
        return d
    return {**d, "t": d["t"] * TIME_UNITS[unit]}


def step(d: dict) -> float | None:
    """The median step of t between consecutive samples of each trajectory, in the file's unit."""
    t = np.asarray(d["t"], dtype=np.float64)
    traj = d.get("traj", np.zeros(len(t)))
    steps = [np.diff(np.sort(t[traj == k])) for k in np.unique(traj)]
    steps = np.concatenate(steps) if steps else np.empty(0)
    steps = steps[steps > 0]
    return float(np.median(steps)) if steps.size else None


@lru_cache(maxsize=16)
def time_scale(system: str) -> float:
    """sqrt(rms(q - mean q) / rms(q̈)) in seconds over 256 of the system's own states."""
    from lagbench import systems

    s = systems.get(system)
    st = s.sample_states(256, np.random.default_rng(0))
    q = st["q"] - st["q"].mean(axis=0)
    acc = np.asarray(s.acceleration(st["q"], st["qdot"]), dtype=np.float64)
    return float(np.sqrt(np.sqrt(np.mean(q ** 2)) / np.sqrt(np.mean(acc ** 2))))


def check_unit(path, d: dict, system: str | None, unit: str = "s") -> None:
    """A ValueError when `unit` is given to a file without times, or the file's step, read in `unit`, is longer
    than `system`'s time scale (module doc)."""
    if "t" not in d:
        if unit != "s":
            raise ValueError(f"--time-unit {unit}: {path} has no t column (a state file: its qdot and qddot are "
                             f"taken as per second); drop --time-unit")
        return
    if system is None:
        return
    h = step(d)
    if h is None:
        return
    scale = time_scale(system)
    seconds = h * TIME_UNITS[unit]
    if seconds <= scale:
        return
    fits = [u for u in TIME_UNITS if u != unit and h * TIME_UNITS[u] <= scale]
    if fits:
        u = fits[0]
        flag = "--time-unit ms" if u == "ms" else "--time-unit s (the default)"
        advice = (f"the times look like {NAMES[u]} (a step of {h * TIME_UNITS[u]:.3g} s): give {flag}; in "
                  f"{NAMES[unit]}, the samples are too far apart for its motion")
    else:
        advice = ("the samples are too far apart for its motion in seconds or milliseconds; give t in seconds "
                  "(or --time-unit ms), sampled faster, or check --system")
    shown = f"{h:.6g} s" if unit == "s" else f"{h:.6g} {unit} ({seconds:.3g} s)"
    raise ValueError(f"{path}: the time step {shown} is {seconds / scale:.3g} x {system}'s time scale of {scale:.2g} s; "
                     f"{advice}")
