""""Model only what a scene needs": per system, its declared structure and what using it buys.

`structure_rows(sizes, inference_rows, progress) -> rows {system, dof, quadratic_kinetic, separable,
local_coupling, actuated, structured_model, general_model, applicable, structured_samples_per_s,
general_samples_per_s, speedup, note}`, from `systems.get(name).structure`:
  local coupling      -> LGN "banded" against LGN "dense" (the inference study's wave rows, largest batch)
  quadratic kinetic   -> DeLaN (M(q), V(q): no velocity Hessian to differentiate) against the LNN "fast"
  neither             -> DeLaN timed anyway but marked applicable = False: it cannot represent a kinetic
                         term that is not quadratic in qdot (the relativistic particle); only the LNN can,
                         so the price of the missing structure is the LNN's cost (the accuracy cost of a
                         mismatched DeLaN comes from the claims' trained units, not from this table).
DeLaN and LNN are timed in JAX, float32, batch `sizes.structure_batch`, MLP `sizes.hidden`, at each
system's default dof (the cost depends only on dof and the architecture, so one timing per dof).
"""
from __future__ import annotations

import numpy as np

from lagbench import systems
from lagbench.models import init_params
from lagbench.speedstudy.evaluators import make_evaluator
from lagbench.speedstudy.inference import model_spec
from lagbench.speedstudy.timing import best_time


def _throughput(kind, dof, sizes):
    spec = model_spec(kind, "fast", dof, sizes.hidden, "float32")
    ev = make_evaluator("jax", spec, init_params(spec, seed=0))
    rng = np.random.default_rng(0)
    b = sizes.structure_batch
    args = ev.prepare(rng.uniform(-1, 1, (b, dof)), rng.uniform(-1, 1, (b, dof)))
    ev.run(args)
    return b / best_time(lambda: ev.run(args), min_time=sizes.min_time)


def _lgn_pair(inference_rows):
    rows = [r for r in inference_rows if r["model"] == "lgn" and r["framework"] == "jax"
            and r["dtype"] == "float32" and r.get("source", "random_init") == "random_init"]
    if not rows:
        return np.nan, np.nan
    b = max(r["batch"] for r in rows)
    pick = {r["formulation"]: r["samples_per_s"] for r in rows if r["batch"] == b}
    return pick.get("banded", np.nan), pick.get("dense", np.nan)


def structure_rows(sizes, inference_rows, progress=None) -> list[dict]:
    cache: dict = {}

    def tp(kind, dof):
        if (kind, dof) not in cache:
            cache[kind, dof] = _throughput(kind, dof, sizes)
        return cache[kind, dof]

    out = []
    for name in systems.names():
        s = systems.get(name)
        st = s.structure
        row = {"system": name, "dof": s.dof, **{k: bool(st.get(k, False)) for k in
               ("quadratic_kinetic", "separable", "local_coupling", "actuated")}}
        if st.get("local_coupling"):
            fast, slow = _lgn_pair(inference_rows)
            row.update(structured_model="lgn/banded", general_model="lgn/dense", applicable=True,
                       note="banded velocity Hessian: O(n) instead of O(n^2) Hessian and O(n^3) solve "
                            "(timed on the wave inference rows; see scaling.csv for the trend in n)")
        else:
            fast, slow = tp("delan", s.dof), tp("lnn", s.dof)
            quad = bool(st.get("quadratic_kinetic"))
            note = ("quadratic kinetic term: DeLaN's M(q), V(q) suffice" if quad else
                    "kinetic term not quadratic in qdot: DeLaN cannot represent it, only the LNN can")
            if st.get("separable"):
                note += "; separable T(qdot) - V(q) (no separable model kind is implemented)"
            row.update(structured_model="delan", general_model="lnn/fast", applicable=quad, note=note)
        row.update(structured_samples_per_s=fast, general_samples_per_s=slow, speedup=fast / slow)
        out.append(row)
        if progress:
            progress.update(1)
    return out


def n_structure_cases() -> int:
    return len(systems.names())
