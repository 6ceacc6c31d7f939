"""How much subnormal floats cost a PyTorch training step, and what flushing them changes.

    python docs/lab/subnormals/step_time.py FOLDER

FOLDER: a trained PyTorch model with its result.json and checkpoint.npz (a run's training cache,
OUT/trained/torch/<key>/, or a `lagbench fit` folder). On one thread, the loss and gradient of one batch of
its protocol's training data (256 states drawn afresh): milliseconds a step with subnormals kept (PyTorch's
own setting) and flushed (lagbench's, `models.torch.subnormals`), at the trained weights and at the same
spec's initial weights; then how many gradient entries the setting changes and by how much.
"""
import json
import sys
import time

import numpy as np
import torch

torch.set_num_threads(1)

from lagbench.files import results as R  # noqa: E402
from lagbench.models.init import init_params  # noqa: E402
from lagbench.models.spec import ModelSpec  # noqa: E402
from lagbench.models.torch.build import build  # noqa: E402
from lagbench.replication.training import data as D  # noqa: E402
from lagbench.replication.training.protocol import Protocol  # noqa: E402
from lagbench.replication.training.train_torch import _to_torch, make_loss  # noqa: E402

torch.set_flush_denormal(False)   # the import above flushes; start from PyTorch's own setting
folder = sys.argv[1]
res = json.load(open(f"{folder}/result.json"))
spec = ModelSpec.from_dict(res.get("spec") or res["model_spec"])
protocol = Protocol.from_dict(res["protocol"])
batch = _to_torch(D.recipe_for(protocol)(protocol, protocol.batch, np.random.default_rng(0)), torch.float32)
loss_fn = make_loss(spec, protocol)


def step(model):
    model.zero_grad()
    loss = loss_fn(model, batch)
    loss.backward()
    return loss.item(), {n: p.grad.detach().clone() for n, p in model.named_parameters() if p.grad is not None}


def ms(model, flush, n=20):
    torch.set_flush_denormal(flush)
    for _ in range(3):
        step(model)
    t = time.perf_counter()
    for _ in range(n):
        step(model)
    torch.set_flush_denormal(False)
    return (time.perf_counter() - t) / n * 1e3


for name, params in (("trained", R.load_npz(f"{folder}/checkpoint.npz")), ("initial", init_params(spec, seed=0))):
    model = build(spec, {k: np.asarray(v) for k, v in params.items()})
    kept, flushed = ms(model, False), ms(model, True)
    print(f"{name} weights: {kept:.1f} ms a step with subnormals kept, {flushed:.1f} ms flushed ({kept / flushed:.1f} x)")
    torch.set_flush_denormal(False)
    (l0, g0) = step(model)
    torch.set_flush_denormal(True)
    (l1, g1) = step(model)
    torch.set_flush_denormal(False)
    differ = sum(int((g0[k] != g1[k]).sum()) for k in g0)
    largest = max(float((g0[k] - g1[k]).abs().max()) for k in g0)
    print(f"  loss {'identical' if l0 == l1 else f'{l0} against {l1}'}; gradient entries that differ: {differ} of "
          f"{sum(g.numel() for g in g0.values())}, by at most {largest:.2g}")
