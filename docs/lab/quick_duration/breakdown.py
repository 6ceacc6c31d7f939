"""Probed training time of every (claim, model, framework) of a profile, both frameworks, at one thread: where
a run's time goes (`replication.run.estimate`'s probes, per unit group rather than per claim).

    python docs/lab/quick_duration/breakdown.py quick    # prints minutes per row; writes breakdown_quick.json here
"""
import json
import sys
from collections import defaultdict
from pathlib import Path

from lagbench.replication.run import estimate as E
from lagbench.replication.run.environment import torch_threads
from lagbench.replication.run.runner import plan

profile = sys.argv[1]
units = plan(profile, frameworks=("jax", "torch"), split="test")
rows, per_step, seen = defaultdict(float), {}, set()
with torch_threads(1):
    for u in units:
        if not u.entry.train:
            continue
        p, spec, group = u.protocol(), u.spec(), E._group(u)
        if group in seen:   # a training shared by several claims counts for the first
            continue
        seen.add(group)
        shape = E._shape(u.framework, spec, p)
        if shape not in per_step:
            if p.cohort:
                per_step[shape] = (E._members_step(u.framework, spec, p, p.cohort), {})
            else:
                per_step[shape] = (E._plain_step(u.framework, spec, p),
                                   {m: E._members_step(u.framework, spec, E.scout_protocol(p), m)
                                    for m, _ in E.scout_parts(p)})
        plain, members = per_step[shape]
        rows[(u.claim.id, u.entry.label, u.framework)] += plain * p.steps + sum(members[m] * n for m, n in E.scout_parts(p))
Path(__file__).with_name(f"breakdown_{profile}.json").write_text(
    json.dumps({"|".join(k): v for k, v in rows.items()}, indent=1) + "\n")
for (claim, label, fw), s in sorted(rows.items(), key=lambda kv: -kv[1]):
    print(f"{claim:18} {label:28} {fw:6} {s / 60:7.1f} min")
print(f"total {sum(rows.values()) / 3600:.2f} h")
