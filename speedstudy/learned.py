"""Learned double-pendulum models rolled out with the ground truth's solvers (part of the rollout study).

`find_trained(folder) -> {label: (spec, params, source)}`: the JAX training cache of a results folder
(`folder/trained/jax/<key>/`, see `replication.training.train`): per model (lnn, baseline) the double-pendulum
acceleration model (data double_pendulum_iid, task acceleration) trained for the most steps; source
"trained:<key>". `tiny_models(sizes)`: where the cache has none, the claim's models at `sizes.target_hidden`
trained for a few seconds with the suite's trainer (source "learned_tiny:<steps> steps").
`learned_rollout_rows(sizes, q0, qd0, errors, base, folder, notes, progress) -> rows` with kind "learned"
(from a cache) or "learned_tiny": diffrax with each solver of `sizes.rollout_solvers` at each rtol of
`sizes.rollout_rtols` (`rollout.field_solver` and `rollout.timed_solve`, as the truth rows: atol = rtol,
PID controller, at most MAX_STEPS steps, all initial states in one vmapped call); the model's parameters are cast to float64 (the rollout judges the learned vector field,
not float32 rounding, which no tolerance below ~1e-7 could resolve). A solve that fails (step limit
MAX_STEPS, non-finite state) gives NaN errors and a note.
"""
from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import jax.numpy as jnp
import numpy as np

import lagbench.models.jax
from lagbench.models import ModelSpec
from lagbench.speedstudy.rollout import MAX_STEPS, field_solver, timed_solve

LABELS = ("lnn", "baseline")
TINY_STEPS = {"tiny": 10, "quick": 600, "full": 3000}


def find_trained(folder) -> dict:
    """{label: (spec, params, source)} from folder/trained/jax/*; the entry with the most steps per label."""
    from lagbench.files.results import load_npz
    from lagbench.replication.training.protocol import Protocol

    found: dict = {}
    for res in sorted(Path(folder).glob("trained/jax/*/result.json")) if folder else []:
        try:
            meta = json.loads(res.read_text())
            proto, spec = Protocol.from_dict(meta["protocol"]), ModelSpec.from_dict(meta["spec"])
        except (OSError, ValueError, KeyError, TypeError):
            continue
        if (proto.data.recipe != "double_pendulum_iid" or proto.task != "acceleration"
                or spec.kind not in LABELS or spec.dof != 2 or spec.extra_inputs or meta.get("failure")
                or not (res.parent / "checkpoint.npz").is_file()):
            continue
        steps = int(meta.get("steps_done", 0))
        if spec.kind not in found or steps > found[spec.kind][0]:
            found[spec.kind] = (steps, spec, res.parent)
    return {k: (spec, load_npz(d / "checkpoint.npz"), f"trained:{d.name} ({steps} steps, hidden "
                f"{'x'.join(map(str, spec.hidden))})") for k, (steps, spec, d) in found.items()}


def tiny_models(sizes, labels=LABELS) -> dict:
    """The claim's models at sizes.target_hidden, trained briefly with the suite's `train_jax.train`."""
    from lagbench.models import init_params
    from lagbench.replication.claims.double_pendulum import MODELS, PLAIN_QUICK
    from lagbench.replication.training.data import BatchStream
    from lagbench.replication.training.train_jax import train

    steps = TINY_STEPS.get(sizes.name, 300)
    proto = PLAIN_QUICK.replace(steps=steps, data=PLAIN_QUICK.data.replace(n_train=128 * 50, n_heldout=256),
                                **{"schedule.every": steps * 2 // 3})
    out = {}
    for entry in MODELS:
        if entry.label in labels:
            spec = ModelSpec(dof=2, hidden=tuple(sizes.target_hidden), dtype=proto.dtype, **entry.spec)
            res = train(spec, init_params(spec, seed=0), proto, BatchStream(proto, 0))
            out[entry.label] = (spec, res.params, f"learned_tiny:{res.steps_done} steps x {proto.batch}, hidden "
                                f"{'x'.join(map(str, spec.hidden))}")
    return out


def learned_rollout_rows(sizes, q0, qd0, errors, base, folder=None, notes=None, progress=None) -> list[dict]:
    models_ = find_trained(folder)
    if set(models_) != set(LABELS):
        models_ = {**tiny_models(sizes, [lb for lb in LABELS if lb not in models_]), **models_}
    y0 = jnp.asarray(np.concatenate([q0, qd0], -1))
    rows = []
    for label in LABELS:
        spec, params, source = models_[label]
        spec64 = dataclasses.replace(spec, dtype="float64")
        model = lagbench.models.jax.build(spec64, params)
        row_kind = "learned_tiny" if source.startswith("learned_tiny") else "learned"
        for solver in sizes.rollout_solvers:
            fn = field_solver(model.acceleration, solver)
            for rtol in sizes.rollout_rtols:
                zT, ok, wall = timed_solve(fn, y0, sizes.rollout_t_end, rtol,
                                           compiled=rtol != sizes.rollout_rtols[0])
                se, ee = errors(np.where(ok[:, None], zT, np.nan))
                if not ok.all() and notes is not None:
                    notes.append(f"rollout {label} {solver} rtol={rtol:g}: {int((~ok).sum())} of {ok.size} "
                                 f"solves failed (step limit {MAX_STEPS} or non-finite state)")
                rows.append({**base, "model": label, "source": source, "solver": solver, "rtol": rtol, "dt": None,
                             "kind": row_kind, "wall_s": wall, "state_err": se, "energy_err": ee})
                if progress:
                    progress.update(1)
    return rows
