"""`lagbench fit`: train a model on a user's data file and write the same result records as a claim.

The run is one unit of a synthetic claim "fit" evaluated by the held-out routine, so its folder
(`OUT/units/fit/<framework>/<model>/seed<k>/`) has result.json, train_log.csv and checkpoint.npz like
every other unit.

Contracts: every option is checked before the file is read or anything is trained, and the output
folder before training (a ValueError naming the option and its valid values). The protocol records
the sha256 of the data file's bytes (`userdata.reference`), so the training cache and the unit's
result are keyed by the file's content: an edited file is trained afresh, never served a stale
model. A verified earlier fit of the same file and options is returned as is; one of other data or
options is kept, renamed `superseded-<time>-seed<k>` (as `lagbench run` does), never overwritten.
"""
from __future__ import annotations

import math
from pathlib import Path

from replication import results as R
from replication import userdata
from replication.claims.base import Claim, ModelEntry
from replication.protocol import Protocol
from replication.units import Unit, run_unit

MODELS = ("lnn", "hnn", "delan", "baseline")
FRAMEWORKS = ("jax", "torch")
LOSSES = ("l1", "mse")


def check_options(model, framework, steps, hidden, batch, lr, seed, loss) -> None:
    """ValueError naming the first bad option and what it accepts."""
    checks = [
        ("--model", model in MODELS, f"one of {', '.join(MODELS)}", model),
        ("--framework", framework in FRAMEWORKS, f"one of {', '.join(FRAMEWORKS)}", framework),
        ("--loss", loss in LOSSES, f"one of {', '.join(LOSSES)}", loss),
        ("--steps", _count(steps, 1), "an integer >= 1", steps),
        ("--batch", _count(batch, 1), "an integer >= 1", batch),
        ("--seed", _count(seed, 0), "an integer >= 0", seed),
        ("--lr", isinstance(lr, (int, float)) and math.isfinite(lr) and lr > 0, "a finite number > 0", lr),
        ("--hidden", len(hidden) > 0 and all(_count(h, 1) for h in hidden),
         "comma-separated layer widths >= 1 such as 128,128", ",".join(map(str, hidden))),
    ]
    for option, ok, valid, value in checks:
        if not ok:
            raise ValueError(f"{option}: {value!r} is not valid; expected {valid}")


def _count(v, low) -> bool:
    return isinstance(v, int) and not isinstance(v, bool) and v >= low


def fit(data, model="lnn", out="results/fit", framework="jax", steps=2000, hidden=(128, 128), batch=256,
        lr=1e-3, seed=0, loss="l1", dtype="float32") -> dict:
    hidden = tuple(hidden)
    check_options(model, framework, steps, hidden, batch, lr, seed, loss)
    out = R.output_folder(out, "--out")
    path = str(Path(data).resolve())
    digest, d = userdata.read(path)
    userdata.check_range(path, d, dtype)
    n, dof = d["q"].shape
    has_tau = "tau" in d
    task = "hamiltonian" if model == "hnn" else "inverse_dynamics" if has_tau and model != "lnn" else "acceleration"
    spec = {"kind": model, "dof": dof, "activation": "softplus",
            "init": "cranmer2020" if model == "lnn" else "xavier"}
    if task == "inverse_dynamics" and model == "baseline":
        spec["extra_inputs"] = dof
    n_train = n - max(1, n // 10)
    protocol = Protocol(data=userdata.reference(path, digest), task=task, coords="qqdot", steps=steps,
                        batch=min(batch, n_train), n_train=n_train, n_heldout=max(1, n // 10), loss=loss, lr=lr,
                        dtype=dtype, log_every=max(1, steps // 100))
    entry = ModelEntry(model, spec, hidden=hidden)
    claim = Claim(id="fit", number=0, paper="user", section="-", title=f"{model} on {Path(data).name}",
                  system=Path(data).name, models=(entry,), protocols={"quick": protocol}, evaluate="heldout",
                  metric="heldout_l1", metric_label="held-out L1", published={}, verdict_rule="none",
                  verdict=lambda v: ("not run", "user data"))
    unit = Unit(claim, entry, framework, seed, "quick")
    from replication.runner import is_current

    if is_current(unit, out):
        return dict(R.load_result(unit.folder(out)), reused=True)
    return run_unit(unit, out)
