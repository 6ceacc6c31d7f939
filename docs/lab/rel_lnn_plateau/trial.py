"""Development trial: how many samples claim 3's LNN on (q, qdot) needs to leave its q-double-dot ~ 0 plateau
with the original's parametrisation (q / 10 before differentiating, velocities held across epochs) at full's
widths (3 x 128) and restarts, trained far longer than full's continuation.

    python docs/lab/rel_lnn_plateau/trial.py OUT [STEPS] [SEEDS]     (SEEDS: development seeds, e.g. 0,1,2)

Trains `lnn` of claim 3 under full's protocol with the continuation at batch 512 for STEPS steps (default
120 000: 6.1e7 samples, about the original's plateau exit) on development seeds SEEDS (default 0), tracking
the development held-out error at 20 points, and writes OUT/curve.csv (seed, step, samples, held-out
loss). Development split only.
"""
import dataclasses
import sys
from pathlib import Path

import pandas as pd

from lagbench.replication.claims import get
from lagbench.replication.claims.resolved import resolved
from lagbench.replication.run import splits
from lagbench.replication.run.executor import run_units
from lagbench.replication.run.units import Unit
from lagbench.replication.training.protocol import Tracking

out = Path(sys.argv[1])
steps = int(sys.argv[2]) if len(sys.argv) > 2 else 120_000
seeds = [int(x) for x in sys.argv[3].split(",")] if len(sys.argv) > 3 else [0]
assert all(splits.of_seed(s) is splits.DEV for s in seeds), "development seeds only"
claim = get("rel_coords")
full = claim.protocols["full"]
trial = full.replace(steps=steps, batch=512, log_every=1000, tracking=Tracking(every=max(1000, steps // 20 // 1000 * 1000)),
                     data=full.data.replace(n_train=512 * 3000, n_heldout=20_000))
claim = dataclasses.replace(claim, protocols={**claim.protocols, "full": trial})
units = [Unit(claim, resolved(claim, "full").model("lnn").entry, "jax", s, "full") for s in seeds]
run_units(units, out, "full", progress=True, jobs=1)
rows = []
for u in units:
    log = pd.read_csv(u.folder(out) / "train_log.csv")
    col = next(c for c in log.columns if "heldout" in c)
    log = log.dropna(subset=[col])
    for r in log.itertuples():
        rows.append({"seed": u.seed, "step": int(r.step), "samples": int(r.step) * trial.batch,
                     "heldout_loss": float(getattr(r, col))})
pd.DataFrame(rows).to_csv(out / "curve.csv", index=False)
print(pd.DataFrame(rows).to_string(index=False))
