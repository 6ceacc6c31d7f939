"""DeLaN's cost against the degrees of freedom: its forward and inverse model, in JAX and in PyTorch.

`delan_dof_rows(dofs=DOFS, batch=BATCH, hidden=HIDDEN, seconds=SECONDS, frameworks=FRAMEWORKS) -> rows`
{framework, method, dof, batch, hidden, dtype, threads, us_per_sample, samples_per_s, ratio}:
  method "acceleration": the forward model, qddot = M^-1 (tau - c - g) from (q, qdot, tau);
  method "inverse_dynamics": the inverse model, tau = M qddot + c + g from (q, qdot, qddot);
  us_per_sample: microseconds per sample of the fastest call on `batch` random float32 states (q ~ U[-pi, pi),
  qdot ~ U[-1, 1), tau and qddot ~ N(0, 1); the cost does not depend on the values);
  ratio: us_per_sample over that of the first dof in `dofs`, same framework and method (1 there).
The model is the speed study's DeLaN (`speedstudy.inference.model_spec`: softplus, Xavier init), MLP `hidden`
(default the DeLaN paper's 2 x 64, as the DeLaN claim). JAX calls the model's jitted methods (compiled on a
first call outside the timing, XLA's default threads); PyTorch runs them eagerly under torch.no_grad with
`TORCH_THREADS` intra-op threads. The dofs of one framework and method are timed interleaved, round by
round (`timing.interleaved_best`, `seconds` of rounds per dof), so the ratios are taken in one run under
the same load; absolute times are this machine's and are never compared across runs.

DeLaN's one trunk pass carries the d forward tangents dh/dq_k beside h, so its MLP work grows about as
(1 + d) times a plain pass; the heads give d (d + 1) / 2 entries of Lc and its d tangents; the forward
model adds a d x d solve.

`write(rows, path)` writes the rows as CSV (atomically). Run it:
`python -m lagbench.speedstudy.delan_dof --out delan_dof.csv [--dofs 2,4,7] [--batch 1024] [--hidden 64,64]
[--seconds 1.0] [--frameworks jax,torch]`; it prints the ratios. Not a stage of `lagbench bench`.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

DOFS = (2, 4, 7)
BATCH = 1024
HIDDEN = (64, 64)
SECONDS = 1.0
FRAMEWORKS = ("jax", "torch")
METHODS = ("acceleration", "inverse_dynamics")
COLUMNS = ("framework", "method", "dof", "batch", "hidden", "dtype", "threads", "us_per_sample",
           "samples_per_s", "ratio")


def _inputs(dof: int, batch: int, seed: int = 0) -> tuple:
    rng = np.random.default_rng(seed)
    q = rng.uniform(-np.pi, np.pi, (batch, dof))
    qdot = rng.uniform(-1.0, 1.0, (batch, dof))
    third = rng.normal(size=(batch, dof))  # tau for the forward model, qddot for the inverse model
    return tuple(x.astype(np.float32) for x in (q, qdot, third))


def _call(framework: str, method: str, dof: int, batch: int, hidden: tuple):
    """A no-argument call that runs `method` of a DeLaN on one batch and blocks, made ready (and compiled)."""
    from lagbench.models import init_params
    from lagbench.speedstudy.inference import model_spec
    from lagbench.speedstudy.timing import jax_ready, torch_ready

    spec = model_spec("delan", "-", dof, hidden, "float32")
    params = init_params(spec, seed=0)
    arrays = _inputs(dof, batch)
    if framework == "jax":
        import jax.numpy as jnp

        from lagbench.models.jax.build import build

        model = build(spec, params)
        fn = jax_ready(getattr(model, method), *(jnp.asarray(x) for x in arrays))
    else:
        import torch

        from lagbench.models.torch.build import build

        model = build(spec, params)
        fn = torch_ready(getattr(model, method), *(torch.as_tensor(x) for x in arrays))
    fn()  # JAX: compiles; PyTorch: a first eager call
    return fn


def delan_dof_rows(dofs=DOFS, batch: int = BATCH, hidden=HIDDEN, seconds: float = SECONDS,
                   frameworks=FRAMEWORKS) -> list[dict]:
    """The rows of the module docstring, for every framework x method x dof."""
    from lagbench.speedstudy.timing import TORCH_THREADS, interleaved_best, torch_threads

    dofs, hidden = tuple(int(d) for d in dofs), tuple(int(h) for h in hidden)
    if not dofs or min(dofs) < 1 or batch < 1:
        raise ValueError("delan_dof_rows needs dofs >= 1 and batch >= 1")
    rows = []
    for fw in frameworks:
        if fw not in FRAMEWORKS:
            raise ValueError(f"unknown framework {fw!r}; valid: {', '.join(FRAMEWORKS)}")
        with torch_threads(TORCH_THREADS if fw == "torch" else None):
            for method in METHODS:
                fns = {d: _call(fw, method, d, batch, hidden) for d in dofs}
                best = interleaved_best(fns, min_rounds=3, budget_s=seconds * len(dofs))
                for d in dofs:
                    rows.append({"framework": fw, "method": method, "dof": d, "batch": int(batch),
                                 "hidden": "x".join(map(str, hidden)), "dtype": "float32",
                                 "threads": TORCH_THREADS if fw == "torch" else "XLA default",
                                 "us_per_sample": 1e6 * best[d] / batch, "samples_per_s": batch / best[d],
                                 "ratio": best[d] / best[dofs[0]]})
    return rows


def write(rows: list[dict], path) -> Path:
    import pandas as pd

    from lagbench.files.results import write_csv

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    write_csv(path, pd.DataFrame(rows, columns=list(COLUMNS)))
    return path


def _ints(text: str) -> tuple:
    return tuple(int(x) for x in text.split(",") if x.strip())


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m lagbench.speedstudy.delan_dof", description=__doc__.splitlines()[0])
    ap.add_argument("--out", required=True, help="the CSV file to write")
    ap.add_argument("--dofs", type=_ints, default=DOFS, help="comma-separated degrees of freedom (default 2,4,7)")
    ap.add_argument("--batch", type=int, default=BATCH)
    ap.add_argument("--hidden", type=_ints, default=HIDDEN, help="MLP widths (default 64,64)")
    ap.add_argument("--seconds", type=float, default=SECONDS, help="seconds of timing rounds per dof")
    ap.add_argument("--frameworks", default=",".join(FRAMEWORKS))
    args = ap.parse_args(argv)
    rows = delan_dof_rows(args.dofs, args.batch, args.hidden, args.seconds, tuple(args.frameworks.split(",")))
    path = write(rows, args.out)
    for r in rows:
        print(f"{r['framework']:>5} {r['method']:<16} dof {r['dof']:>2}: {r['us_per_sample']:9.3f} us/sample, "
              f"x{r['ratio']:.2f} of dof {rows[0]['dof']}")
    print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
