"""Pilot (not registered): a second phase of the filtered acceleration loss (`Protocol.filter_loss`) after an LNN
fit's acceleration loss, from its trained parameters, at a one-cycle schedule (the fit's shape) of STEPS steps,
batch BATCH and peak rate LR; then, before and after, the friction read as b / |c| (c the least-squares factor
of the velocity Hessian against the mass matrix), that matrix's relative residual and the q-double-dot error
against the exact dynamics (friction 0.2) on the development test file's first 4 000 rows.

    python docs/lab/recording_defaults/filtered_finish_pilot.py OUT/s0-lnn STEPS BATCH LR
"""
import dataclasses
import glob
import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from model_friction import EXACT, TRUE_FRICTION

from lagbench.files import user_data
from lagbench.replication.evaluation.adapters import adapter
from lagbench.replication.fit.dissipation import softplus
from lagbench.replication.fit.filter_rows import training_rows
from lagbench.replication.fit.load import Padded, load_fitted
from lagbench.replication.training import train_jax
from lagbench.replication.training.data import BatchStream
from lagbench.replication.training.protocol import Protocol
from lagbench.replication.training.protocol_parts import FilterLoss

folder, steps, batch, lr = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), float(sys.argv[4])
unit = glob.glob(folder + "/units/fit/jax/*/seed*")[0]
f = load_fitted(unit)
res = json.load(open(unit + "/result.json"))
d = res["eval_config"]["derivatives"]
p = Protocol.from_dict(res["protocol"])
part = FilterLoss(d["window"], d["polyorder"])
n = len(training_rows(p.data.recipe, part)["q"])
p = dataclasses.replace(p, data=dataclasses.replace(p.data, n_train=n))
p2 = dataclasses.replace(p, scouting=None, steps=steps, batch=batch, filter_loss=FilterLoss(d["window"], d["polyorder"]),
                         schedule=dataclasses.replace(p.schedule, lr=lr), log_every=max(1, steps // 10))
t0 = time.time()
out = train_jax.train(f.spec, {k: np.asarray(v) for k, v in f.params.items()}, p2, BatchStream(p2, 0))
secs = time.time() - t0
test = user_data.rows(glob.glob(folder + "/data/val-test-*.csv")[0], "test")
q, qd = (np.asarray(test[k], np.float64)[:4000] for k in ("q", "qdot"))
m_true = np.asarray(EXACT.mass_matrix(q))
exact = np.asarray(EXACT.acceleration(q, qd)) - np.einsum("nij,nj->ni", np.linalg.inv(m_true), TRUE_FRICTION * qd)
for name, params in (("before", f.params), ("after", out.params)):
    g = dataclasses.replace(f, params=params, model=Padded(adapter(f.framework, f.spec, params)))
    h = np.asarray(g.model.velocity_hessian(q, qd), np.float64)
    c = float(np.sum(h * m_true) / np.sum(m_true * m_true))
    b = softplus(np.asarray(params["dissipation.raw"], np.float64))
    pred = np.asarray(g.acceleration(q, qd), np.float64)
    print(folder, name, f"steps {steps} batch {batch} lr {lr} ({secs:.0f} s)", "friction", (b / abs(c)).round(4).tolist(),
          "residual", round(float(np.linalg.norm(h - c * m_true) / np.linalg.norm(h)), 3),
          "err vs exact", round(float(np.sqrt(((pred - exact) ** 2).mean() / (exact ** 2).mean())), 4),
          "failure", out.failure, flush=True)
