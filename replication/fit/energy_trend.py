"""`--dissipation auto`: whether a recording's training trajectories lose energy, read off the data with the
true energy function (`--system` or `--energy`).

`measure(r, energy) -> Trend`: the energy E(q, q̇) along each trajectory of the rows `r` (the prepared,
filtered q and q̇ of the training rows, with their traj and t), the least-squares slope of E against t, and
that slope times the trajectory's duration made relative to the trajectory's energy of motion
K = E(q, q̇) - E(q, 0), averaged over its rows: the share of its motion's energy the trajectory loses. K is zero at
rest whatever E's zero is (the double pendulum's E is negative near rest), and for a mechanical system it is the
kinetic energy, so a viscous friction b on a coordinate of inertia I reads about -2 (b / I) x duration.
`decide(trend) -> (chosen, why)`: the data lose energy when the median relative change over the trajectories
is below `-DROP` and at least `MAJORITY` of the trajectories have a negative slope (noise moves single
trajectories either way; friction moves them all one way). `choose(mode, capable, r, energy, forced)` is
what a fit records (eval_config["dissipation"]): mode, chosen, why and the figures; `auto` is off without an
energy function or trajectories, for a kind without a dissipation, and on data with torques (their work changes
the energy as friction does). `for_fit(o, prep)`: `choose` for a fit's options `o` on its prepared rows `prep`.

Calibration (`lagbench simulate --system S --set friction=F`, seeds 0-3; the rows a fit prepares, at its
`--window auto` derivatives; the median relative change over a file's trajectories, lowest to highest over the seeds):

| recording | friction 0 | friction 0.05 | friction 0.2 |
|---|---|---|---|
| pendulum, 8 x 5 s at 50 Hz, noise 0.001 | -0.0001 to 0.0005 | -0.49 to -0.47 | -2.0 to -1.8 |
| pendulum, 8 x 5 s, noise 0.0087 (0.5 degree), dropped 0.02 | -0.0045 to 0.0039 | -0.46 to -0.42 | -1.9 to -1.8 |
| pendulum, 3 x 5 s, noise 0.0087, dropped 0.02 | -0.0041 to 0.0068 | -0.46 to -0.38 | -1.8 to -1.5 |
| pendulum, 8 x 5 s, noise 0.03 | -0.016 to 0.015 | -0.44 to -0.39 | -1.8 to -1.5 |
| double pendulum, 8 x 4 s at 100 Hz, noise 0.001, dropped 0.02 | -0.0005 to 0.0001 | -0.41 to -0.32 | -1.5 to -1.3 |
| double pendulum, 8 x 4 s, noise 0.0087, dropped 0.02 | -0.0021 to 0.0016 | -0.40 to -0.32 | -1.5 to -1.3 |
| double pendulum, 3 x 4 s, noise 0.0087, dropped 0.02 | -0.0064 to -0.0001 | -0.42 to -0.30 | -1.3 to -1.2 |
| double pendulum, 16 x 1 s, noise 0.0087, dropped 0.02 | -0.0013 to 0.0050 | -0.092 to -0.067 | -0.37 to -0.27 |

With friction every trajectory loses energy on every seed (share 1.0); without, the share losing ranges from 0.12
to 1.0 (all three of the 3 double-pendulum trajectories lose a little), so the share alone does not decide.
`DROP` = 0.03 is twice the widest conservative reading (noise 0.03) and five times those at noise 0.0087, and under
half the least friction's (0.05 on 1 s recordings: -0.067); a single conservative trajectory read at most 0.056
(1 s, noise 0.0087).
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

from lagbench.files import user_data
from lagbench.models.kinds import CAPABILITIES
from lagbench.replication.fit.trajectories import starts

DROP = 0.03       # the median relative change below -DROP ...
MAJORITY = 2 / 3  # ... with at least this share of the trajectories losing energy: the data lose energy
MODES = ("auto", "on", "off")
NO_ENERGY = "no energy function to check the data with: give --system or --energy, or --dissipation on"


class Trend(NamedTuple):
    relative: np.ndarray   # per trajectory: the slope of E x its duration / its mean energy of motion
    trajectories: int      # measured (those with at least 3 rows and some motion)

    @property
    def median(self) -> float:
        return float(np.median(self.relative)) if self.trajectories else float("nan")

    @property
    def losing(self) -> float:
        """The share of the trajectories whose energy falls."""
        return float(np.mean(self.relative < 0)) if self.trajectories else float("nan")


def measure(r: dict, energy) -> Trend:
    """The energy trend of each trajectory of the rows `r` (q, qdot, t and traj, a trajectory file's rows)."""
    q, qdot, t = (np.asarray(r[k], np.float64) for k in ("q", "qdot", "t"))
    e = np.asarray(energy(q, qdot), np.float64)
    motion = e - np.asarray(energy(q, np.zeros_like(qdot)), np.float64)
    out = []
    for idx in starts(r.get("traj", np.zeros(len(t)))):
        tt, k = t[idx], float(np.mean(motion[idx]))
        if idx.size < 3 or not k > 0 or np.ptp(tt) <= 0:
            continue
        slope = np.polyfit(tt - tt.mean(), e[idx], 1)[0]
        out.append(slope * np.ptp(tt) / k)
    return Trend(np.array(out), len(out))


def decide(trend: Trend) -> tuple[bool, str]:
    """(the data lose energy, the reason in words)."""
    if not trend.trajectories:
        return False, "no training trajectory with motion to measure the energy along"
    figures = (f"median relative energy change {trend.median:+.3g} over {trend.trajectories} training trajectories, "
               f"{trend.losing:.0%} of them losing energy")
    rule = f"on below -{DROP:g} with at least {MAJORITY:.0%} losing"
    if trend.median < -DROP and trend.losing >= MAJORITY:
        return True, f"the training data lose energy: {figures} ({rule})"
    return False, f"the training data keep their energy: {figures} ({rule})"


def choose(mode, capable: bool, rows=None, energy=None, forced: bool = False) -> dict:
    """What a fit records of its dissipation: {"mode", "chosen", "why"} and, where `auto` measured the rows,
    "median", "losing" and "trajectories". `capable`: the model kind has a dissipation; `rows`: the training
    rows of a trajectory file (None for a state file); `energy`: E(q, qdot) or None; `forced`: the data hold
    torques, whose work changes the energy too (then `auto` is off, saying so)."""
    mode = {True: "on", False: "off"}.get(mode, mode)
    if mode != "auto":
        return {"mode": mode, "chosen": mode == "on", "why": "as given"}
    if not capable:
        return {"mode": mode, "chosen": False, "why": "the model kind has no dissipation (its q-double-dot is "
                "free-form)"}
    if forced:
        return {"mode": mode, "chosen": False, "why": "the data hold torques, whose work changes the energy as "
                "friction does; give --dissipation on or off"}
    if energy is None:
        return {"mode": mode, "chosen": False, "why": NO_ENERGY}
    if rows is None:
        return {"mode": mode, "chosen": False, "why": "a state file has no trajectories to follow the energy "
                "along; give --dissipation on or off"}
    trend = measure(rows, energy)
    chosen, why = decide(trend)

    def g(x):   # 4 significant digits: a record to read
        return float(f"{x:.4g}") if np.isfinite(x) else None

    return {"mode": mode, "chosen": chosen, "why": why, "median": g(trend.median), "losing": g(trend.losing),
            "trajectories": trend.trajectories}


def describe(record: dict) -> str:
    """A fit's dissipation record (eval_config["dissipation"]) in words."""
    return f"{'on' if record.get('chosen') else 'off'} (--dissipation {record.get('mode')}): {record.get('why')}"


def for_fit(o, prep) -> dict:
    """`choose` for the options `o` of a fit on its prepared rows `prep`: the training rows of a trajectory file,
    read with the true energy of `--system` or `--energy` (measured only for `auto` on a kind with a
    dissipation, on data without torques)."""
    capable = CAPABILITIES[o.model].dissipation
    if o.dissipation != "auto" or not capable:
        return choose(o.dissipation, capable)
    from lagbench.replication.fit.evaluate import energy_function

    energy = energy_function({"energy": o.energy, "system": o.system}, prep.dof)
    recording = any(prep.trajectories.values())
    rows = user_data.rows(prep.reference, "train") if recording and energy is not None else None
    return choose("auto", True, rows, energy, forced=prep.has_tau)
