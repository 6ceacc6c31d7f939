"""`lagbench fit`: train a model on a user's data file and write the same result records as a claim.

The run is one unit of a synthetic claim "fit" evaluated by the held-out routine, so its folder
(`OUT/units/fit/<framework>/<model>/seed<k>/`) has result.json, train_log.csv and checkpoint.npz like
every other unit.
"""
from __future__ import annotations

from pathlib import Path

from replication.claims.base import Claim, ModelEntry
from replication.protocol import Protocol
from replication.units import Unit, run_unit
from replication.userdata import load

MODELS = ("lnn", "hnn", "delan", "baseline")


def fit(data, model="lnn", out="results/fit", framework="jax", steps=2000, hidden=(128, 128), batch=256,
        lr=1e-3, seed=0, loss="l1", dtype="float32") -> dict:
    if model not in MODELS:
        raise ValueError(f"unknown model {model!r}; valid: {', '.join(MODELS)}")
    path = str(Path(data).resolve())
    d = load(path)
    n, dof = d["q"].shape
    has_tau = "tau" in d
    task = "hamiltonian" if model == "hnn" else "inverse_dynamics" if has_tau and model != "lnn" else "acceleration"
    spec = {"kind": model, "dof": dof, "activation": "softplus",
            "init": "cranmer2020" if model == "lnn" else "xavier"}
    if task == "inverse_dynamics" and model == "baseline":
        spec["extra_inputs"] = dof
    n_train = n - max(1, n // 10)
    protocol = Protocol(data=f"file:{path}", task=task, coords="qqdot", steps=steps, batch=min(batch, n_train),
                        n_train=n_train, n_heldout=max(1, n // 10), loss=loss, lr=lr, dtype=dtype,
                        log_every=max(1, steps // 100))
    entry = ModelEntry(model, spec, hidden=tuple(hidden))
    claim = Claim(id="fit", number=0, paper="user", section="-", title=f"{model} on {Path(data).name}",
                  system=Path(data).name, models=(entry,), protocols={"quick": protocol}, evaluate="heldout",
                  metric="heldout_l1", metric_label="held-out L1", published={}, verdict_rule="none",
                  verdict=lambda v: ("not run", "user data"))
    return run_unit(Unit(claim, entry, framework, seed, "quick"), out)
