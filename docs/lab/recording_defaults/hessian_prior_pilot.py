"""Pilot (not registered): an LNN fit whose loss also keeps the velocity Hessian constant in q-dot, as the true
Lagrangian's (the mass matrix M(q)) is. The fit's training loss, for an LNN on the acceleration loss, gains

    LAMBDA * mean_rows |H(q, q-dot) - H(q, SPEED q-dot)|^2 / mean_rows |H(q, q-dot)|^2

(Frobenius norms; relative, so the Lagrangian's free scale does not weigh it), by wrapping
`replication.training.train_jax.make_loss` in this process; everything else is `lagbench fit` at its defaults
(JAX), run in-process on the recording folder's data/train.csv and data/val.csv, into OUT/s<SEED>-lnn_prior<LAMBDA>,
with the training cache in that folder so that no other fit reuses these trainings.

    python docs/lab/recording_defaults/hessian_prior_pilot.py OUT LAMBDA SEED [SPEED] [-- more fit options]

PRIOR_ROWS=N reads the prior on the batch's first N rows only (default: every row), so that it costs a fraction
of a step; the folder's name then ends in _rN.

Then `python docs/lab/recording_defaults/summary.py OUT` and `damping_by_speed.py OUT/s<SEED>-lnn_prior<LAMBDA>`.
"""
import os
import sys
from pathlib import Path

out, lam, seed = Path(sys.argv[1]), float(sys.argv[2]), int(sys.argv[3])
rest = sys.argv[4:]
speed = float(rest.pop(0)) if rest and rest[0] != "--" else 0.0
extra = rest[1:] if rest and rest[0] == "--" else []
rows = int(os.environ.get("PRIOR_ROWS", "0")) or None
folder = out / (f"s{seed}-lnn_prior{lam:g}" + ("" if speed == 0.0 else f"_s{speed:g}") + (f"_r{rows}" if rows else ""))
os.environ["LAGBENCH_CACHE"] = str(folder / ".pilot-cache")

import jax.numpy as jnp  # noqa: E402

from lagbench import cli  # noqa: E402
from lagbench.replication.training import train_jax  # noqa: E402

plain = train_jax.make_loss


def make_loss(spec, protocol):
    base = plain(spec, protocol)
    if spec.kind != "lnn" or protocol.task != "acceleration" or protocol.trajectory_loss or protocol.filter_loss:
        return base
    print(f"hessian prior: lambda {lam:g}, second speed {speed:g} x q-dot, rows {rows or 'all'}", flush=True)

    def loss_fn(model, batch):
        q, qdot = batch["q"][:rows], batch["qdot"][:rows]
        h = model.velocity_hessian(q, qdot)
        h2 = model.velocity_hessian(q, speed * qdot)
        prior = jnp.mean(jnp.sum((h - h2) ** 2, (-2, -1))) / jnp.mean(jnp.sum(h ** 2, (-2, -1)))
        return base(model, batch) + lam * prior
    return loss_fn


if lam > 0:   # LAMBDA 0: the plain fit, as a control run the same way
    train_jax.make_loss = make_loss
cli.main(["fit", "--data", str(out / "data" / "train.csv"), "--test", str(out / "data" / "val.csv"),
          "--system", "double_pendulum", "--model", "lnn", "--seed", str(seed), "--out", str(folder), "--quiet",
          *extra])
