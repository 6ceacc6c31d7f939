"""When a rollout has diverged: the suite's one rule, for the commands' console lines, the reports and figures.

An error measured against the data's own scale (an energy error over the mean kinetic energy, a state error
normalised by the spread of the data's states) that is not finite or exceeds `DIVERGED` has diverged: a
thousand times the data's own scale is beyond any motion of the system, so the number says only that the
rollout blew up. It is flagged "diverged", counted apart, never printed as a number nor averaged in.

`is_diverged(x) -> bool`: the rule for one such error (None, no value, is not diverged).
`SCALED`: the metrics (without their set prefix) that are such errors.
`shown(x, spec=".4g") -> str`: the value formatted, or "diverged".
`diverged_trajectories(err) -> (B,) bool`: the rows of errors (B, T) over time that ever diverged.
`rollouts_words(metrics, where) -> str | None`: "k of n rollouts diverged" for the evaluation set `where`
("heldout", "test": its metrics `<where>_n_diverged` of `<where>_n_trajectories`), or None where none did.
`flagged(metrics, where) -> str | None`: that, and each `SCALED` metric of the set that diverged, in words;
`note(metrics)` the console's " (DIVERGED: ...)" of each set that has one, else "".
"""
from __future__ import annotations

import math

import numpy as np

DIVERGED = 1e3
SCALED = ("energy_err_final", "energy_err_max", "energy_err_final_median", "learned_energy_drift")


def is_diverged(x) -> bool:
    if x is None or isinstance(x, bool):
        return False
    x = float(x)
    return not math.isfinite(x) or abs(x) > DIVERGED


def shown(x, spec: str = ".4g") -> str:
    return "diverged" if is_diverged(x) else format(float(x), spec)


def diverged_trajectories(err) -> np.ndarray:
    err = np.asarray(err, np.float64)
    return ~np.all(np.isfinite(err) & (np.abs(err) <= DIVERGED), axis=-1)


def rollouts_words(metrics: dict, where: str) -> str | None:
    n, of = metrics.get(f"{where}_n_diverged"), metrics.get(f"{where}_n_trajectories")
    return f"{int(n)} of {int(of)} rollouts diverged" if n and of else None


def flagged(metrics: dict, where: str) -> str | None:
    words = [rollouts_words(metrics, where)]
    words += [f"{where}_{k} diverged" for k in SCALED if is_diverged(metrics.get(f"{where}_{k}"))]
    return "; ".join(w for w in words if w) or None


def note(metrics: dict, sets=("heldout", "test")) -> str:
    """" (DIVERGED: ...)" for each of the evaluation `sets` whose rollouts diverged (`flagged`), else ""."""
    return "".join(f" (DIVERGED: {blown})" for where in sets if (blown := flagged(metrics, where)))
