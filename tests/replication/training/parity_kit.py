"""Cross-framework training parity: run one table row in JAX and in PyTorch, compare every step.

A row (`parity_rows.Row`) is a model spec, a protocol and a mode: "one" (one model, `train`), "members"
(K models as one program, `train_members`) or "scouted" (restarts over inits, `scouting.train_scouted`).
`trace(framework, row)` runs it through `Recorder`, a trainer (the `train` / `train_members` pair that
`scouting` calls) that records every phase it runs: per member, the log (log_every = 1: loss, grad_norm,
lr, skipped_steps at every step) and the parameters after every step (a loop hook). JAX's compiled steps
are shared across runs of one process (`_jax_step`, keyed by what `train_jax.make_step` reads), so rows
and tests that train the same spec under the same loss, optimiser and clip compile once. The Hessian
probe (a logging diagnostic, not training) is off.

`compare(a, b) -> (diffs, mismatches)`: diffs = the largest relative difference over all phases, members
and steps of the loss, the gradient norm and the parameters (all of them as one vector, `_params_rel`), and
`steps` (steps compared per member, phases summed); mismatches: what must be equal and is not (step
counts, learning rates, skipped-step counts, failures, the scout chosen).

`python tests/replication/training/parity_kit.py [ROW ...]` prints the parity table (every row, slow ones too).
"""
from __future__ import annotations

import functools
import sys

import numpy as np

from lagbench.models import init_params
from lagbench.replication.training import loop, scouting, train_jax, train_torch
from lagbench.replication.training.data import BatchStream

_JAX_STEPS: dict = {}


def _jax_step(spec, protocol, members: bool):
    key = (spec, protocol.objective_key(), members)   # what the compiled step depends on, as train_jax keys it
    if key not in _JAX_STEPS:
        _JAX_STEPS[key] = (train_jax.make_members_step if members else train_jax.make_step)(spec, protocol)
    return _JAX_STEPS[key]


class Recorder:
    """A trainer for one framework that records every run (`phases`: per run, per member, {log, params};
    `modes`: per run, its step mode)."""

    def __init__(self, framework: str):
        self.fw, self.phases, self.modes = framework, [], []

    def _stepper(self, spec, params, protocol, members: bool):
        module = train_jax if self.fw == "jax" else train_torch
        cls = module.Members if members else module.Stepper
        extra = {"step": _jax_step(spec, protocol, members)} if self.fw == "jax" else {}
        stepper = cls(spec, params, protocol, **extra)
        stepper.look = None
        return stepper

    def _record(self, outcomes, params):
        self.modes.append(outcomes[0].step_mode)
        self.phases.append([{"log": o.log, "params": [p[i] for p in params], "failure": o.failure}
                            for i, o in enumerate(outcomes)])

    def train(self, spec, params, protocol, stream, on_log=None, hooks=(), snapshot=None):
        seen = []
        keep = (lambda k, stepper, info: seen.append([stepper.params()]))   # noqa: E731
        out = loop.train(self._stepper(spec, params, protocol, False), protocol, stream, on_log, (keep, *hooks),
                         snapshot=snapshot)
        self._record([out], seen)
        return out

    def train_members(self, spec, params_list, protocol, streams, on_log=None, hooks=(), snapshot=None,
                      start_state=None):
        seen = []
        keep = (lambda k, stepper, info: seen.append(stepper.params()))   # noqa: E731
        outs = loop.train_members(self._stepper(spec, params_list, protocol, True), protocol, streams, on_log,
                                  (keep, *hooks), snapshot=snapshot, start_state=start_state)
        self._record(outs, seen)
        return outs


def trace(framework: str, row) -> Recorder:
    rec, spec, p = Recorder(framework), row.spec, row.protocol
    if row.mode == "one":
        rec.train(spec, init_params(spec, seed=row.seeds[0]), p, BatchStream(p, row.seeds[0]))
    elif row.mode == "members":
        rec.train_members(spec, [init_params(spec, seed=s) for s in row.seeds], p,
                          [BatchStream(p, s) for s in row.seeds])
    elif row.mode == "scouted":
        rec.outcome = scouting.train_scouted(rec, spec, p, row.seeds[0])
    else:
        raise ValueError(f"unknown mode {row.mode!r}")
    return rec


def _rel(a, b) -> float:
    a, b = np.asarray(a, np.float64), np.asarray(b, np.float64)
    scale = max(np.max(np.abs(a), initial=0.0), np.max(np.abs(b), initial=0.0))
    return float(np.max(np.abs(a - b), initial=0.0) / scale) if scale > 0 else 0.0


def _params_rel(qa: dict, qb: dict) -> float:
    """||a - b|| / max(||a||, ||b||) over all parameters (one vector). Not per element: in float32 a gradient
    component that cancels to rounding level (an L1 loss's signs summing to 0 on a bias: 0 in one framework,
    1e-8 in the other) is turned by Adam into a step of 0 or about lr, so single small parameters part at once
    while the model does not."""
    sq = lambda d: sum(float(np.sum(np.asarray(v, np.float64) ** 2)) for v in d.values())   # noqa: E731
    diff = sum(float(np.sum((np.asarray(qa[k], np.float64) - np.asarray(qb[k], np.float64)) ** 2)) for k in qa)
    scale = max(sq(qa), sq(qb))
    return float(np.sqrt(diff / scale)) if scale > 0 else 0.0


def step_diffs(ma: dict, mb: dict) -> np.ndarray:
    """(steps, 3): the relative differences of loss, gradient norm and parameters at each step of one
    member's record in two frameworks (as many steps as both have)."""
    rows = []
    for ra, rb, qa, qb in zip(ma["log"], mb["log"], ma["params"], mb["params"], strict=False):
        rows.append((_rel(ra["loss"], rb["loss"]), _rel(ra["grad_norm"], rb["grad_norm"]),
                     _params_rel(qa, qb)))
    return np.asarray(rows, np.float64).reshape(-1, 3)


def compare(a: Recorder, b: Recorder):
    diffs, bad = {"loss": 0.0, "grad_norm": 0.0, "params": 0.0, "steps": 0}, []
    if len(a.phases) != len(b.phases):
        return diffs, [f"phases: {len(a.phases)} != {len(b.phases)}"]
    for n, (pa, pb) in enumerate(zip(a.phases, b.phases, strict=True)):
        for i, (ma, mb) in enumerate(zip(pa, pb, strict=True)):
            where = f"phase {n} member {i}"
            if (ma["failure"] is None) != (mb["failure"] is None) or len(ma["log"]) != len(mb["log"]):
                bad.append(f"{where}: {len(ma['log'])} vs {len(mb['log'])} steps, failures "
                           f"{ma['failure']} / {mb['failure']}")
                continue
            for ra, rb in zip(ma["log"], mb["log"], strict=True):
                same = ("step", "lr", "skipped_steps")
                if any(ra.get(k) != rb.get(k) for k in same):
                    bad.append(f"{where}: {[ra.get(k) for k in same]} != {[rb.get(k) for k in same]} ({same})")
            d = step_diffs(ma, mb).max(axis=0, initial=0.0)
            for j, k in enumerate(("loss", "grad_norm", "params")):
                diffs[k] = max(diffs[k], float(d[j]))
            if i == 0:
                diffs["steps"] += len(ma["log"])
    sa, sb = getattr(a, "outcome", None), getattr(b, "outcome", None)
    if sa is not None and sa.scouting["chosen"] != sb.scouting["chosen"]:
        bad.append(f"scout chosen: {sa.scouting['chosen']} != {sb.scouting['chosen']}")
    return diffs, bad


@functools.cache
def cached_trace(framework: str, row) -> Recorder:
    """`trace`, once per (framework, row) in a process (tests that look at one run again share it)."""
    return trace(framework, row)


def run_row(row):
    return compare(cached_trace("jax", row), cached_trace("torch", row))


def within(row, diffs) -> bool:
    return all(diffs[k] <= row.tolerance[k] for k in ("loss", "grad_norm", "params"))


def table(rows) -> str:
    """The parity table (markdown), one line per row; each line also goes to stderr as it is done."""
    head = ("| row | kind | formulation | task (coords) | loss | schedule | mode | dtype | steps | loss rel. | "
            "grad norm rel. | params rel. | tolerance | passes |")
    lines = [head, "|" + "---|" * (head.count("|") - 1)]
    for row in rows:
        d, bad = run_row(row)
        p, tol = row.protocol, row.tolerance
        form = row.spec.own.formulation if row.spec.kind in ("lnn", "lgn") else "-"
        task = p.task + (f" ({p.data.coords})" if p.task == "hamiltonian" else "")
        guard = " + guard" if p.guard else ""
        steps = {"one": f"{d['steps']}", "members": f"{d['steps']} (x{len(row.seeds)} members)",
                 "scouted": f"{p.scouting.steps} (x{p.scouting.count} scouts) + {d['steps'] - p.scouting.steps}"}[row.mode]
        lines.append(f"| {row.name} | {row.spec.kind} | {form} | {task} | {p.loss} | {p.schedule} | "
                     f"{row.mode}{guard} | {p.dtype} | {steps} | {d['loss']:.1e} | {d['grad_norm']:.1e} | "
                     f"{d['params']:.1e} | {tol['loss']:.0e} / {tol['grad_norm']:.0e} / {tol['params']:.0e} | "
                     f"{'yes' if within(row, d) and not bad else 'NO ' + '; '.join(bad[:2])} |")
        print(lines[-1], file=sys.stderr, flush=True)
    return "\n".join(lines)


if __name__ == "__main__":
    from parity_rows import ROWS

    wanted = sys.argv[1:]
    print(table([r for r in ROWS if not wanted or r.name in wanted]))
