"""How long one `quick` training spends compiling: `python docs/lab/quick_duration/compile_share.py CLAIM MODEL
[SEED]` runs the unit's JAX training with its protocol cut to 40 steps (scouting too, tracking every 20) and
prints the wall time and the compile durations `jax.monitoring` reports. Run it twice with a
JAX_COMPILATION_CACHE_DIR set to see what the persistent cache saves a second seed."""
import collections
import sys
import time

import jax.monitoring as mon

from lagbench.replication.run.runner import plan
from lagbench.replication.training.train import run_training

acc = collections.Counter()
mon.register_event_duration_secs_listener(lambda ev, d, **kw: acc.__setitem__(ev, acc[ev] + d))
claim, model = sys.argv[1], sys.argv[2]
seed = int(sys.argv[3]) if len(sys.argv) > 3 else 0
unit = next(u for u in plan("quick", claims=[claim], frameworks=("jax",)) if u.entry.label == model)
p = unit.protocol()
change = {"steps": 40, "log_every": 10}
if p.scouting:
    change["scouting.steps"] = 40
if p.tracking:
    change["tracking.every"] = 20
t = time.time()
run_training("jax", unit.spec(), p.replace(**change), seed)
print(claim, model, "seed", seed, "wall", round(time.time() - t, 1), "s")
for k, v in acc.most_common(6):
    print(f"  {v:7.2f} s {k}")
