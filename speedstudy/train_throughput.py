"""Training throughput of a claim's model under its own protocol, per framework and device, through the
suite's one training loop (`replication.training.train.run_training`), as a `paper` run trains it.

`measure(claim, model, profile, frameworks, device, steps)` trains `steps` optimiser steps of the model's
protocol (its schedule, guard and loss; restarts off: one run) from seed 0 and returns one row per
framework: samples per second over the steps after the first (`TrainOutcome.step_seconds`: the first step
compiles), the step mode (JAX jit; PyTorch compiled where the protocol's training would be, or eager, with
the reason if a compile failed), and where it computed. It says nothing of
accuracy: the steps are a few of the protocol's.

`python -m lagbench.speedstudy.train_throughput --device gpu --out FILE.csv` (defaults: the double-pendulum LNN of
the `paper` profile, 3 x 600, batch 512, both frameworks, 200 steps) writes the rows as CSV and prints them.
"""
from __future__ import annotations

import argparse
import sys

import pandas as pd

from lagbench.replication.claims import get as get_claim
from lagbench.replication.claims.resolved import resolved
from lagbench.replication.training import compile_torch
from lagbench.replication.training import device as dev
from lagbench.replication.training.train import run_training


def measure(claim: str = "dp_loss", model: str = "lnn", profile: str = "paper", frameworks=("jax", "torch"),
            device: str = "auto", steps: int = 200) -> pd.DataFrame:
    from lagbench.replication.run.units import Unit

    c = get_claim(claim)
    entry = resolved(c, profile).model(model).entry   # as it runs: the adopted tuning applied
    where = dev.check(device, frameworks)
    rows = []
    for fw in frameworks:
        unit = Unit(c, entry, fw, 0, profile)
        spec, protocol = unit.spec(), unit.protocol()
        p = protocol.replace(steps=steps, log_every=max(steps // 10, 1), scouting=None, tracking=None,
                             data=protocol.data.replace(n_train=protocol.batch * steps))
        # PyTorch compiles where the protocol's own training would (its full length decides, not these steps)
        with compile_torch.like(spec, protocol), dev.placed(fw, where[fw]):
            out = run_training(fw, spec, p, 0)
        timed = max(out.steps_done - 1, 1)
        rows.append({"claim": claim, "model": model, "profile": profile, "framework": fw,
                     "device": where[fw], "device_name": dev.describe(fw, where[fw])["name"],
                     "hidden": "x".join(map(str, spec.hidden)), "batch": p.batch, "dtype": p.dtype, "steps": out.steps_done,
                     "step_mode": out.step_mode, "train_time_s": out.train_time_s,
                     "samples_per_s": timed * p.batch / out.step_seconds if out.step_seconds > 0 else float("nan"),
                     "final_loss": out.log[-1]["loss"] if out.log else float("nan"),
                     "failure": (out.failure or {}).get("kind")})
    return pd.DataFrame(rows)


def main(argv=None) -> int:
    a = argparse.ArgumentParser(prog="python -m lagbench.speedstudy.train_throughput", description=__doc__.split("\n\n")[0])
    a.add_argument("--claim", default="dp_loss")
    a.add_argument("--model", default="lnn")
    a.add_argument("--profile", default="paper")
    a.add_argument("--frameworks", default="jax,torch")
    a.add_argument("--device", default="auto", choices=dev.CHOICES)
    a.add_argument("--steps", type=int, default=200)
    a.add_argument("--out", help="CSV file to write (default: print only)")
    args = a.parse_args(argv)
    try:
        df = measure(args.claim, args.model, args.profile, tuple(args.frameworks.split(",")), args.device, args.steps)
    except (KeyError, ValueError) as e:
        print(f"train_throughput: error: {e}", file=sys.stderr)
        return 2
    if args.out:
        df.to_csv(args.out, index=False)
    print(df.to_string(index=False))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
