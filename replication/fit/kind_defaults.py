"""`lagbench fit`'s defaults per model kind, read from the suite's own protocols (and, for an LNN on a
trajectory file, the budget of a registered fit study: `ON_RECORDINGS`), and sized down for a system smaller
than the one the kind's protocol was chosen on (`SMALL`).

A fit trains as the claim that tuned its kind does: the registered protocol of that claim's model under the
`quick` profile with its adopted `lagbench tune` choice (`replication.claims.get` applies it), so the LNN
gets the double-pendulum claims' restarts over initialisations with halving and fallbacks, their gradient-spike guard,
schedule, width and budget, and a change of a claim's protocol or tuning moves these defaults with it.

`SOURCES`: (kind, task) -> (claim id, model label): the LNN and an acceleration baseline from claim 1 (the
double pendulum, where the q-double-dot plateau is), the HNN from the HNN claim's pendulum, DeLaN and an
inverse-dynamics baseline (data with tau) from the two-link arm's claim.
`ON_RECORDINGS`: (kind, task) -> the factor on the claim's steps for a trajectory file, where a registered fit
study chose a longer budget for recorded trajectories than the claim's i.i.d. states need
(`docs/decisions/fit_budget.md`: every form got the same candidates; the LNN's held-out error chose 3 x).
`NOISY_RECORDINGS`: (kind, task) -> the position noise (`trajectories.position_noise`: what `--window auto`
estimates on q, the mean over coordinates, in q's units) at and above which a trajectory file whose
q-double-dot is estimated from q trains the claim's steps without restart fallbacks instead of
`ON_RECORDINGS`'s budget: on noisy recordings the longer budget rolls out worse (a registered study on
simulated double-pendulum recordings at three noise levels, `docs/decisions/fit_budget.md`).
`SMALL`: data with fewer coordinates than the system of the kind's claim (the LNN's and the q-double-dot
baseline's: the double pendulum's 2; DeLaN's and the torque baseline's: the two-link arm's 2; the HNN's: the
pendulum's 1, so never) train without restarts, for the claim's steps (no `ON_RECORDINGS` factor) and stop
early: when `SMALL["patience"]` held-out evaluations in a row (`HELDOUT_CHECKS` over the steps) bring no
improvement of `MIN_IMPROVEMENT`, then anneal over the steps the patience spans (`replication.fit.task`
builds the `EarlyStop`; `docs/decisions/fit_budget.md` has the measurements). A system as large as
the claim's keeps the claim's budget and no early stop.
`defaults(kind, task, recording=False, dof=None, noise=None) -> dict`: fit option name -> value for every option
in `FROM_PROTOCOL` and `patience`, and the restarts' `restart_fraction` (their steps / the protocol's) and
`restart_lr_ratio` (their peak / the protocol's); `dof`: the data's coordinates (None: as the claim's); `noise`:
the recording's position noise (None: not estimated). `small(kind, task, dof) -> bool`: whether `SMALL` applies;
`noisy(kind, task, noise) -> bool`: whether the noise reaches `NOISY_RECORDINGS`'s switch, and
`noisy_recording(kind, task, recording, dof, noise)` whether a file trains that budget. `source(kind, task, recording=False,
dof=None, given=(), noise=None) -> str`: where the defaults come from, for the console (`given`: the options
set by the user, whose defaults it does not name).

What the claims set for their system rather than for training stays the user's choice: wrapping angles
(the double pendulum's q are angles; a user's may not be), and the claims' fixed input scale becomes
`--input-scale auto` (1 / each input's standard deviation over the training rows) where a claim scales its
inputs. The restarts' length and peak rate follow `--steps` and `--lr` in the claim's proportions (as a
tuned rate scales a claim's restarts with it); their one-cycle starts at OneCycle's default phase, as the
claims' restarts do.
"""
from __future__ import annotations

import math
from functools import cache

from lagbench.replication.training.schedules import OneCycle

PROFILE = "quick"
SOURCES = {("lnn", "acceleration"): ("dp_loss", "lnn"), ("baseline", "acceleration"): ("dp_loss", "baseline"),
           ("hnn", "hamiltonian"): ("hnn_energy", "hnn_pendulum"), ("delan", "inverse_dynamics"): ("delan_arm", "delan"),
           ("delan", "acceleration"): ("delan_arm", "delan"), ("baseline", "inverse_dynamics"): ("delan_arm", "ff")}
ON_RECORDINGS = {("lnn", "acceleration"): 3}
# the geometric mean of the estimated position noise of the study's 0.001 rad recording (3 x won) and of its
# 0.003 rad one (1 x won): docs/lab/recording_defaults/switch.py
NOISY_RECORDINGS = {("lnn", "acceleration"): 0.00172}
SMALL = {"restarts": None, "patience": 10}   # and the claim's steps: see `small`
HELDOUT_CHECKS = 100   # a fit logs, and its early stop evaluates the held-out rows, this many times over its steps
MIN_IMPROVEMENT = 0.01   # the early stop's least improvement, a fraction of the best held-out error so far
FROM_PROTOCOL = ("steps", "batch", "hidden", "activation", "lr", "schedule", "lr_start", "lr_min_ratio", "weight_decay",
                 "loss", "restarts", "restart_keep", "restart_fallback", "restart_batch", "guard_clip", "guard_skip",
                 "input_scale")


def _entry(kind: str, task: str):
    from lagbench.replication.claims import get
    from lagbench.replication.claims.base import per_profile
    from lagbench.replication.claims.resolved import resolved

    claim_id, label = SOURCES[(kind, task)]
    claim = get(claim_id)
    entry = resolved(claim, PROFILE).model(label).entry   # as it runs: the adopted tuning applied
    return claim, entry, entry.protocol(per_profile(claim.protocols, PROFILE), PROFILE)


def claim_dof(kind: str, task: str) -> int:
    """The coordinates of the system the kind's claim trains on (its data recipe's system)."""
    from lagbench import systems

    return systems.get(_entry(kind, task)[2].data.recipe.removesuffix("_iid")).dof


def small(kind: str, task: str, dof: int | None) -> bool:
    """Data of `dof` coordinates are a smaller system than the kind's claim trains on."""
    return dof is not None and dof < claim_dof(kind, task)


def noisy(kind: str, task: str, noise: float | None) -> bool:
    """A recording's estimated position noise `noise` is at or above the kind's `NOISY_RECORDINGS` switch."""
    return noise is not None and (kind, task) in NOISY_RECORDINGS and noise >= NOISY_RECORDINGS[(kind, task)]


def noisy_recording(kind: str, task: str, recording: bool, dof: int | None, noise: float | None) -> bool:
    """A trajectory file that trains `NOISY_RECORDINGS`'s budget: noisy (`noisy`) and not sized down (`small`)."""
    return recording and not small(kind, task, dof) and noisy(kind, task, noise)


def _steps_factor(kind: str, task: str, recording: bool, dof: int | None = None, is_noisy: bool = False) -> int:
    return ON_RECORDINGS.get((kind, task), 1) if recording and not small(kind, task, dof) and not is_noisy else 1


@cache
def _defaults(kind: str, task: str, recording: bool, dof: int | None, is_noisy: bool) -> tuple:
    _, entry, p = _entry(kind, task)
    one_cycle = isinstance(p.schedule, OneCycle)
    s = p.scouting
    if s is not None and isinstance(s.schedule, OneCycle) and s.schedule.start != OneCycle.start:
        raise ValueError(f"{kind}: the claim's restarts start their one-cycle at phase {s.schedule.start}; fit's start at "
                         f"{OneCycle.start}")
    out = {"steps": p.steps * _steps_factor(kind, task, recording, dof, is_noisy), "batch": p.batch,
           "hidden": entry.widths(PROFILE),
           "activation": entry.spec_fields(PROFILE).get("activation", "softplus"),
           "lr": p.schedule.lr, "schedule": "onecycle" if one_cycle else "constant",
           "lr_start": p.schedule.start if one_cycle else OneCycle.start,
           "lr_min_ratio": p.schedule.min_ratio if one_cycle else OneCycle.min_ratio,
           "weight_decay": p.l2, "loss": p.loss,
           "restarts": s.count if s else None, "restart_keep": s.keep if s else None,
           "restart_fallback": s.fallback if s else None,
           "restart_batch": s.batch if s else None,
           # the restarts' length and peak rate as fractions of the fit's --steps and --lr
           "restart_fraction": s.steps / p.steps if s else None, "restart_lr_ratio": s.schedule.lr / p.schedule.lr if s else None,
           "guard_clip": p.guard.clip if p.guard else None, "guard_skip": p.guard.skip if p.guard else None,
           "input_scale": "auto" if entry.spec_fields(PROFILE).get("input_scale") is not None else None,
           "patience": 0}
    if small(kind, task, dof):   # the restarts' other settings stay the claim's, for a --restarts given
        out.update(SMALL)
    elif is_noisy and recording and s and s.fallback:   # the claim's steps, their restarts without a fallback
        out["restart_fallback"] = 0
    return tuple(out.items())


def defaults(kind: str, task: str, recording: bool = False, dof: int | None = None, noise: float | None = None) -> dict:
    """Fit option -> value, as the claim that tuned this kind trains it under `quick`; with `recording` (a
    trajectory file), the steps times the kind's `ON_RECORDINGS` factor, or, where its position noise `noise`
    is at or above the kind's `NOISY_RECORDINGS` switch, the claim's steps without restart fallbacks; for data
    of `dof` coordinates, fewer than the claim's system has, `SMALL`."""
    return dict(_defaults(kind, task, recording, dof, noisy(kind, task, noise) and not small(kind, task, dof)))


def source(kind: str, task: str, recording: bool = False, dof: int | None = None, given=(),
           noise: float | None = None) -> str:
    claim, entry, _ = _entry(kind, task)
    factor = 1 if "steps" in given else _steps_factor(kind, task, recording, dof, noisy(kind, task, noise))
    noisy_file = noisy_recording(kind, task, recording, dof, noise)
    sized = (f", sized for {dof} coordinate{'s' if dof != 1 else ''} (the claim's system has {claim_dof(kind, task)}): "
             f"{'no restarts, ' if SMALL['restarts'] is None else ''}an early stop at patience {SMALL['patience']} "
             f"(docs/decisions/fit_budget.md)" if small(kind, task, dof) else "")
    return (f"claim {claim.number} ({claim.id}) model {entry.label}, {PROFILE} profile with its adopted tuning"
            + (f", {factor} x its steps on a trajectory file (docs/decisions/fit_budget.md)" if factor != 1 else "")
            + (f", {'its steps and ' if 'steps' not in given else ''}restarts without a fallback on a noisy "
               f"trajectory file (position noise {noise:.3g}, at or above {NOISY_RECORDINGS[(kind, task)]:.3g}: "
               f"docs/decisions/fit_budget.md)" if noisy_file else "")
            + sized)


def fill(o, task: str, recording: bool = False, dof: int | None = None, noise: float | None = None,
         steps_factor: float = 1.0):
    """The options `o` (`options.resolve`'s namespace) with every BY_KIND value set from `defaults(o.model,
    task, recording, dof, noise)`, the default steps times `steps_factor` (rounded up; an even Lagrangian's on a
    noisy recording, `even_velocity.steps_factor`), 0 (off) turned into None for the restarts and the guard, the
    restarts' steps, batch and peak rate from --steps, --batch and --lr where not given; then checked as a whole."""
    from types import SimpleNamespace

    from lagbench.replication.fit import options as fit_options

    d, v = defaults(o.model, task, recording, dof, noise), dict(vars(o))
    given = {k for k, x in v.items() if x is not fit_options.BY_KIND}
    fit_options.check(v)   # the given values, those the kind sets still BY_KIND (the defaults are valid)
    v.update({k: d[k] for k in (*FROM_PROTOCOL, "patience") if k not in given})
    if "steps" not in given and steps_factor != 1:
        v["steps"] = max(1, math.ceil(v["steps"] * steps_factor))
    for k in ("restarts", "guard_clip", "guard_skip"):
        if v[k] == 0:
            v[k] = None
    if not v["restarts"]:
        v.update(restarts=None, restart_keep=None if "restart_keep" not in given else v["restart_keep"],
                 restart_fallback=None if "restart_fallback" not in given else v["restart_fallback"])
    elif "restart_keep" not in given and v["restart_keep"] is not None and v["restart_keep"] >= v["restarts"]:
        v["restart_keep"] = None   # the kind's halving does not fit fewer restarts than it keeps
    if v["restarts"] and "restart_fallback" not in given and v["restart_fallback"]:
        v["restart_fallback"] = min(v["restart_fallback"], (v["restart_keep"] or v["restarts"]) - 1)   # as many as fit
    if v["restarts"]:
        v["restart_steps"] = v["restart_steps"] or max(2, round(v["steps"] * (d["restart_fraction"] or 1 / 8)))
        v["restart_batch"] = v["restart_batch"] or v["batch"]
        v["restart_lr"] = v["restart_lr"] or v["lr"] * (d["restart_lr_ratio"] or 1.0)
    if isinstance(v["hidden"], list):
        v["hidden"] = tuple(v["hidden"])
    fit_options.check(v)   # the relations (restarts and their halving) with the defaults in
    return SimpleNamespace(**v)
