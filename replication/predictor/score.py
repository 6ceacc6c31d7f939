"""Score a predictor from outside the suite: any function mapping NumPy (q, qdot), each (N, d), to qddot (N, d).

`setup(system, profile) -> Setup`: how the suite scores its own models on `system`: the first claim (in
claim order) with a model that learns q-double-dot of `system` from (q, qdot) alone, evaluated by
"energy_rollout" where a claim does so, else by "heldout"; that model's protocol (its held-out set) and the
claim's evaluation config (rollout initial conditions, horizon, step) under `profile`.
`score(function, system, profile="quick", out=None, label=None) -> dict`: the predictor evaluated exactly as
that model is, on the test split (`replication.run.splits.TEST`: its held-out draw and initial conditions):
one-step errors beside the null predictor's, rollouts with the suite's RK4, the energy error along them,
valid prediction time against the chaos floor (`replication.evaluation.valid_time`), and the seconds per
state of one call. Its status is "failed" (its failure: "non-finite on k of n held-out states") where the
function returns a non-finite q-double-dot on any held-out state; an exception it raises, or an output of the
wrong type or shape, is one line (`lagbench.files.user_functions`), and so is a call that runs past
`call_limit` seconds. `on_call(done, total)` follows every call (`calls_of(setup)`: how many scoring makes).
With `out`, the record is written to OUT/predict/<system>/<label>/ (result.json and the evaluation's tables). `lagbench evaluate --predict module:function --system NAME` runs it.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from lagbench.files import results as R
from lagbench.files.user_functions import (
    UserCodeError,
    array_of,
    call,
    nonfinite_failure,
    nonfinite_rows,
    time_limit,
    wrong,
)
from lagbench.replication.evaluation.registry import EVALUATION_VERSION, EVALUATIONS
from lagbench.replication.evaluation.rollout import steps
from lagbench.replication.evaluation.routines import Context, _floor, _truth, heldout_of, system_of, truth_key
from lagbench.replication.run import environment as env
from lagbench.replication.run.splits import TEST

SCORED_BY = ("energy_rollout", "heldout")   # the evaluations a (q, qdot) -> qddot predictor can be put through


@dataclass(frozen=True)
class Setup:
    claim: object
    entry: object
    protocol: object
    evaluate: str
    cfg: dict


@dataclass(frozen=True)
class External:
    """What the evaluation routines read of a model's spec: a predictor from outside is of no suite kind."""
    dof: int
    kind: str = "external"


class Predictor:
    """A user's function as the evaluation routines call a model: float64 (..., d) arrays in and out. Each call
    runs under `limit` seconds (None: no limit) and is counted (`calls`); `on_call(calls)` follows each one."""

    def __init__(self, function, dof: int, name: str, limit: float | None = None, on_call=None):
        self.function, self.dof, self.name, self.limit, self.on_call = function, dof, name, limit, on_call
        self.calls, self.seconds = 0, 0.0

    def _past_limit(self, what: str, n: int) -> UserCodeError:
        done = (f"; the {self.calls} before it took {self.seconds / self.calls:.3g} s on average" if self.calls
                else "")
        return UserCodeError(f"--predict {self.name}: {what} on {n} states ran past --call-limit {self.limit:g} s "
                             f"(call {self.calls + 1}{done}); make the function faster, or give a larger --call-limit")

    def acceleration(self, q, qdot, extra=None):
        q, qdot = np.asarray(q, np.float64), np.asarray(qdot, np.float64)
        n = int(np.prod(q.shape[:-1]))
        what = f"{getattr(self.function, '__name__', 'the function')}(q, qdot)"
        t0 = time.perf_counter()
        with time_limit(self.limit, lambda: self._past_limit(what, n)):
            out = call("--predict", self.name, what, self.function, q.reshape(n, self.dof), qdot.reshape(n, self.dof))
        self.calls, self.seconds = self.calls + 1, self.seconds + time.perf_counter() - t0
        if self.on_call is not None:
            self.on_call(self.calls)
        out = array_of("--predict", self.name, what, out)
        if out.shape != (n, self.dof):
            raise wrong("--predict", self.name, f"{what} must map q, qdot of shape (N, {self.dof}) to qddot of shape "
                        f"(N, {self.dof}); for N = {n} it gave shape {out.shape}")
        return out.reshape(q.shape)


def _candidates(profile: str):
    from lagbench.replication.claims import CLAIMS
    from lagbench.replication.claims.resolved import resolved

    for c in CLAIMS.values():
        if c.evaluate not in SCORED_BY:
            continue
        for m in (x.entry for x in resolved(c, profile).models):   # as they run: the adopted tuning applied
            if not (m.train and m.runs_in(profile)):
                continue
            p, fields = m.protocol(c.protocol(profile), profile), m.spec_fields(profile)
            if (p.task == "acceleration" and p.data.coords == "qqdot" and not fields.get("extra_inputs")
                    and not fields.get("lorentz_factor")):
                yield p.data.recipe.removesuffix("_iid"), Setup(c, m, p, c.evaluate, c.evaluation_config(profile))


def setup(system: str, profile: str = "quick") -> Setup:
    from difflib import get_close_matches

    from lagbench import systems

    if system not in systems.names():   # a misspelt name is named as such, not as a system no claim scores
        near = get_close_matches(system, systems.names(), 1)
        raise ValueError(f"--system {system}: unknown system{f' (did you mean {near[0]}?)' if near else ''}; "
                         f"valid: {', '.join(systems.names())}")
    found = {}
    for name, s in _candidates(profile):
        if name not in found or (found[name].evaluate != "energy_rollout" and s.evaluate == "energy_rollout"):
            found[name] = s
    if system not in found:
        raise ValueError(f"--system {system}: no claim scores a (q, qdot) -> qddot model on it under profile "
                         f"{profile}; valid: {', '.join(sorted(found))}")
    return found[system]


def calls_of(s: Setup) -> int:
    """How many calls scoring makes into the function: the held-out set twice (its time per state, then the
    evaluation), and for "energy_rollout" four per RK4 step of the rollouts (batched over initial conditions)."""
    if s.evaluate != "energy_rollout":
        return 2
    t = np.linspace(0.0, s.cfg["t_end"], s.cfg["n_t"])
    return 2 + 4 * sum(steps(b - a, s.cfg["dt"], "split", np.float64)[0] for a, b in zip(t[:-1], t[1:], strict=True))


def score(function, system: str, profile: str = "quick", out=None, label: str | None = None, name: str = "",
          call_limit: float | None = None, on_call=None) -> dict:
    """The predictor's record (see the module's doc); `name` is how errors name it (its module:function).
    `call_limit`: seconds one call may take (`time_limit`; None: no limit); `on_call(done, total)` after each
    call, `total` from `calls_of` (for a progress bar)."""
    if call_limit is not None and not (isinstance(call_limit, int | float) and math.isfinite(call_limit)
                                       and call_limit > 0):
        raise ValueError(f"--call-limit: {call_limit!r} is not valid; expected a number of seconds > 0")
    s = setup(system, profile)
    named = getattr(function, "__name__", "")
    label = label or (named if named.isidentifier() else "predictor")   # a lambda's "<lambda>" names no folder
    if not label.replace("_", "").replace("-", "").isalnum():
        raise ValueError(f"--label {label}: use letters, digits, - and _ only (it names a folder)")
    folder = R.output_folder(out) / "predict" / system / label if out is not None else None
    dof = system_of(s.protocol).dof
    total = calls_of(s)
    model = Predictor(function, dof, name or label, call_limit,
                      None if on_call is None else lambda done: on_call(done, max(done, total)))
    ctx = Context(claim=s.claim, entry=s.entry, framework="numpy", spec=External(dof), params=None,
                  protocol=s.protocol, profile=profile, cfg=s.cfg, model=model, split=TEST)
    batch = heldout_of(ctx)
    if s.evaluate == "energy_rollout":   # the truth first (cached): the progress bar's estimate times the calls alone
        _truth(*truth_key(ctx))
        _floor(*truth_key(ctx))
    t0 = time.perf_counter()
    held = model.acceleration(batch["q"], batch["qdot"])
    per_state = (time.perf_counter() - t0) / len(batch["q"])
    failure = nonfinite_failure(nonfinite_rows(held), len(held))   # a NaN is never scored "ok"
    ev = EVALUATIONS[s.evaluate](ctx)
    record = {"schema": R.SCHEMA, "claim": "predict", "system": system, "predictor": name or label, "model": label,
              "split": TEST.name, "profile": profile, "status": "ok" if failure is None else "failed", "failure": failure,
              "scored_like": {"claim": s.claim.id, "model": s.entry.label, "evaluation": s.evaluate},
              "metrics": {**ev.metrics, "predict_s_per_state": per_state}, "counters": ev.counters,
              "protocol": s.protocol.to_dict(), "eval_config": s.cfg, "evaluation_version": EVALUATION_VERSION,
              "versions": env.versions(), "commit": env.commit(), "hardware": env.hardware(), "created": env.now()}
    if folder is None:
        return record
    files = {n: R.write_csv(folder / n, df) for n, df in ev.tables.items()}
    if ev.arrays:
        files["arrays.npz"] = R.write_npz(folder / "arrays.npz", ev.arrays)
    return {**R.write_json(Path(folder) / "result.json", {**record, "files": files}, checksum=True), "folder": str(folder)}
