"""Whether a fit's LNN has a Lagrangian even in q-dot (`--even-velocity`, `Lnn.even_velocity`): L = (N(q, qdot)
+ N(q, -qdot)) / 2, the time-reversal symmetry of a mechanical system without magnetic forces, so that a learned
dissipation is the model's only force odd in q-dot.

`MODES`: auto, on, off. `choose(mode, kind, noisy, dissipation) -> record` ({"mode", "chosen", "why"}): `auto`
is on for an LNN that learns a dissipation (`--dissipation`, given or chosen) on a trajectory file whose
estimated position noise is at or above the kind's `kind_defaults.NOISY_RECORDINGS` switch, where a registered
study measured it (`docs/decisions/fit_budget.md`: on simulated double-pendulum recordings at 0.5 degree of
noise an MLP of q-dot put half to three quarters of its odd force outside the friction; the even Lagrangian at
half the steps, the same network work, read the friction on every seed, the larger per-angle error 9.5 % on
the median seed against the plain LNN's 14 %, and rolled out with 0.82 x its error); off otherwise. With it on and the steps not given, a noisy recording trains
`STEPS_FACTOR` x the kind's steps (`kind_defaults.fill`). `describe(record)` in words for the console and the
report; `steps_factor(record, noisy)` the factor on the default steps; `for_fit(o, options, task, recording,
dof, noise)` the choice for a fit's resolved options once its dissipation is chosen.
"""
from __future__ import annotations

from lagbench.replication.fit import kind_defaults

MODES = ("auto", "on", "off")
# the even Lagrangian's steps on a noisy recording, as a fraction of the plain LNN's there: the same network work
# (each step evaluates the network at +qdot and -qdot)
STEPS_FACTOR = 0.5
WHERE = "an LNN learning a dissipation on a noisy trajectory file (docs/decisions/fit_budget.md)"


def choose(mode, kind: str, noisy: bool, dissipation: bool) -> dict:
    mode = {True: "on", False: "off"}.get(mode, mode)
    if mode != "auto":
        return {"mode": mode, "chosen": mode == "on", "why": "as given"}
    if kind != "lnn":
        return {"mode": mode, "chosen": False, "why": "for the LNN only"}
    if not dissipation:
        return {"mode": mode, "chosen": False, "why": "no dissipation learned: on only for " + WHERE}
    if not noisy:
        return {"mode": mode, "chosen": False, "why": "not a noisy recording: on only for " + WHERE}
    return {"mode": mode, "chosen": True, "why": WHERE}


def steps_factor(record: dict, noisy: bool) -> float:
    """The factor on the kind's default steps: `STEPS_FACTOR` for an even Lagrangian on a noisy recording."""
    return STEPS_FACTOR if record["chosen"] and noisy else 1.0


def describe(record: dict) -> str:
    return (f"{'on' if record.get('chosen') else 'off'} (--even-velocity {record.get('mode')}): {record.get('why')}"
            + (f"; {record['steps']} steps, {STEPS_FACTOR:g} x the plain LNN's: the same network work"
               if record.get("steps") else ""))


def for_fit(o, options: dict, task: str, recording: bool, dof: int, noise) -> tuple:
    """(the fit's options `o` with `even_velocity` chosen and, where that changes the default steps, the kind's
    defaults filled again with the factor from the given `options`; the choice's record)."""
    from lagbench.replication.fit import options as fit_options

    noisy = kind_defaults.noisy_recording(o.model, task, recording, dof, noise)
    record = choose(o.even_velocity, o.model, noisy, bool(o.dissipation))
    factor = steps_factor(record, noisy)
    if factor != 1 and "steps" not in options:
        filled = kind_defaults.fill(fit_options.resolve(options), task, recording, dof, noise, steps_factor=factor)
        filled.periodic, filled.dissipation, filled.loss_target = o.periodic, o.dissipation, o.loss_target
        o = filled
        record["steps"] = o.steps
    o.even_velocity = record["chosen"]
    return o, record
