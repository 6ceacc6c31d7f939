"""Inference study: q-double-dot throughput and error for every model x framework x formulation.

`inference_cases(sizes) -> list[Case]` and `run_case(case, states, min_time) -> list[row]`; a row is
{system, model, formulation, framework, mode, threads, dtype, batch, samples_per_s, error, source, hidden,
ops} (ops: kernels per call, `Evaluator.ops`, counted at the smallest batch; the ratio notes use it).
mode: "jit" (JAX), "eager" or "aoti" (PyTorch compiled ahead of time, `evaluators.TorchAotEvaluator`; the
kinds in AOT_KINDS, both systems' truths included, where `sizes.torch_compile`), "traced" (the kinds in
TRACED_KINDS, whose torch.func does not export: traced into ATen operators, then compiled per batch size,
`evaluators.TorchTracedEvaluator`), "numpy". threads: PyTorch rows are
timed at each of TORCH_THREAD_CHOICES intra-op threads (1 and all cores) and keep the faster (the column
says which: on shared cores a 2-thread pool can lose 10-100x to other processes' load, idle it wins at
large batches); JAX rows run XLA's default pool ("default"). A PyTorch row also holds
jax_paired_samples_per_s: the same operation in JAX, timed in the same interleaved rounds (the ratio
table compares those two, `tables.paired_best`).
Systems: the double pendulum (every kind but the graph network, plus the SymPy ground truth as model
"truth" in NumPy, JAX and PyTorch) and the wave equation on a periodic grid of `sizes.wave_n` points (LGN dense vs banded, and
truth; batches capped at `GRID_NODES` // n states). Models are untrained (seed-0 random init of the spec, source "random_init"): their error is
large; that is expected. `trained_cases(out)` adds double-pendulum models found as checkpoints under
OUT/units/<claim>/<framework>/<model>/seed0/ (source "trained:<claim>"), evaluated in their own
framework and dtype, which gives the error column its meaning. Error (one per case, on the largest
batch's states, shared by its rows): median of |q''_pred - q''_true| / |q''_true| against float64 NumPy
ground truth on the same states.
"""
from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from lagbench import systems
from lagbench.models import ModelSpec, init_params
from lagbench.models.spec import CAPABILITIES
from lagbench.speedstudy.evaluators import make_evaluator, median_rel_error
from lagbench.speedstudy.timing import (  # noqa: F401 - TORCH_THREAD_CHOICES is read as inference.*
    PAIRED_ROUNDS,
    TORCH_THREAD_CHOICES,
    TORCH_THREADS,
    best_time,
    interleaved_best,
    torch_thread_choices,
    torch_threads,
)

GRID_NODES = 8192  # wave batches are capped at GRID_NODES // n states (the dense path holds n + 1 tangents)
DP_KINDS = (("truth", "sympy"), ("lnn", "paper"), ("lnn", "fast"), ("hnn", "-"), ("delan", "-"),
            ("baseline", "-"))
WAVE_KINDS = (("truth", "sympy"), ("lgn", "dense"), ("lgn", "banded"))
# kinds that export (torch.export + AOTInductor); the paper LNN and the dense LGN differentiate with torch.func
# from the models' capability table (`models.spec.CAPABILITIES`), plus the SymPy truth (hand-written maths)
AOT_KINDS = (("truth", "sympy"), *((k, f) for k, c in CAPABILITIES.items() for f, how in c.torch_compile.items()
                                   if how == "aot"))
TRACED_KINDS = tuple((k, f) for k, c in CAPABILITIES.items() for f, how in c.torch_compile.items() if how == "traced")
@dataclass
class Case:
    system: str
    system_kw: dict
    model: str
    formulation: str
    framework: str
    dtype: str
    batches: tuple
    spec: ModelSpec | None = None
    params: dict | None = None
    source: str = "random_init"
    extra: dict = field(default_factory=dict)
    mode: str | None = None  # None: the framework's default (jit, eager); "aoti" / "traced": PyTorch compiled


def model_spec(kind: str, formulation: str, dof: int, hidden: tuple, dtype: str, **kw) -> ModelSpec:
    """The study's spec of a kind: softplus, the LNN paper's empirical init; the baseline ReLU + Xavier (the
    LNN paper's baseline); DeLaN softplus + Xavier (the empirical init's sqrt(n) output scale makes a
    random DeLaN mass matrix singular in float32)."""
    act, init = ("relu", "xavier") if kind == "baseline" else ("softplus", "cranmer2020")
    init = "xavier" if kind == "delan" else init
    form = formulation if CAPABILITIES[kind].formulations else "fast"
    return ModelSpec(kind=kind, dof=dof, hidden=tuple(hidden), activation=act, init=init, dtype=dtype,
                     formulation=form, **kw)


def _frameworks(kind):
    return ("numpy", "jax", "torch") if kind == "truth" else ("jax", "torch")


def inference_cases(sizes) -> list[Case]:
    cases = []
    wave_batches = tuple(sorted({min(b, GRID_NODES // sizes.wave_n) for b in sizes.batches}))
    plan = (("double_pendulum", {}, 2, DP_KINDS, sizes.hidden, sizes.batches),
            ("wave", {"n": sizes.wave_n}, sizes.wave_n, WAVE_KINDS, sizes.lgn_hidden, wave_batches))
    for system, kw, dof, kinds, hidden, batches in plan:
        for kind, form in kinds:
            for dtype in sizes.dtypes:
                spec = None if kind == "truth" else model_spec(kind, form, dof, hidden, dtype)
                params = None if spec is None else init_params(spec, seed=0)
                extra = {"hidden": "x".join(map(str, hidden)) if spec else ""}
                for fw in _frameworks(kind):
                    cases.append(Case(system, kw, kind, form, fw, dtype, batches, spec, params, extra=extra))
                if sizes.torch_compile and (kind, form) in AOT_KINDS:
                    cases.append(Case(system, kw, kind, form, "torch", dtype, batches, spec, params, extra=extra,
                                      mode="aoti"))
                if sizes.torch_compile and (kind, form) in TRACED_KINDS:
                    cases.append(Case(system, kw, kind, form, "torch", dtype, batches, spec, params, extra=extra,
                                      mode="traced"))
    return cases


def trained_cases(out: Path, batches: tuple) -> list[Case]:
    """Double-pendulum checkpoints of a previous `lagbench run` in OUT/units (seed 0 only)."""
    from lagbench.files.results import load_npz
    from lagbench.replication.training.protocol import Protocol

    cases = []
    for res_path in sorted(Path(out).glob("units/*/*/*/seed0/result.json")):
        try:
            res = json.loads(res_path.read_text())
        except (OSError, ValueError):
            continue
        try:
            protocol = Protocol.from_dict(res["protocol"])
        except (KeyError, TypeError, ValueError):
            continue
        ckpt = res_path.parent / "checkpoint.npz"
        if res.get("status") != "ok" or "model_spec" not in res or not protocol.data.recipe.startswith("double_pendulum") \
                or protocol.task != "acceleration" or not ckpt.is_file():
            continue
        spec = ModelSpec.from_dict(res["model_spec"])
        if spec.dof != 2 or spec.extra_inputs:
            continue
        fw = res.get("framework", res_path.parts[-4])
        form = spec.own.formulation if CAPABILITIES[spec.kind].formulations else "-"
        cases.append(Case("double_pendulum", {}, spec.kind, form,
                          fw, spec.dtype, batches, spec, load_npz(ckpt), source=f"trained:{res.get('claim')}",
                          extra={"hidden": "x".join(map(str, spec.hidden))}))
    return cases


def states_for(system: str, kw: dict, n: int, seed: int = 0) -> dict:
    """n states of the system's default distribution and their float64 ground-truth accelerations."""
    s = systems.get(system, **kw)
    st = s.sample_states(n, np.random.default_rng(seed))
    return {"q": st["q"], "qdot": st["qdot"], "qddot": s.acceleration(st["q"], st["qdot"], backend="numpy")}


def _timed_paired(ev, args, jev, jargs, min_time) -> tuple[float, object, float]:
    """(fastest PyTorch seconds, its threads, fastest JAX seconds): a PyTorch row and the same operation in
    JAX timed in the same interleaved rounds (`timing.interleaved_best`), at each thread count."""
    best, jax_best = (float("inf"), None), float("inf")
    for n in torch_thread_choices():
        with torch_threads(n):
            ev.run(args)  # the pool at this size
            got = interleaved_best({"torch": lambda: ev.run(args), "jax": lambda: jev.run(jargs)},
                                   min_rounds=PAIRED_ROUNDS, budget_s=2 * min_time)
        best, jax_best = min(best, (got["torch"], n)), min(jax_best, got["jax"])
    return best[0], best[1], jax_best


def run_case(case: Case, states: dict, min_time: float) -> list[dict]:
    """The case's rows, one per batch. A PyTorch row also times the same operation in JAX in the same
    interleaved rounds (`jax_paired_samples_per_s`): the ratio table compares those two, so that a burst of
    load from other processes on these shared cores hits both sides alike."""
    s = systems.get(case.system, **case.system_kw) if case.model == "truth" else None
    ev = make_evaluator(case.framework, case.spec, case.params, kind="truth" if s else case.model,
                        dtype=case.dtype, system=s, mode=case.mode)
    jev = (make_evaluator("jax", case.spec, case.params, kind="truth" if s else case.model, dtype=case.dtype,
                          system=s) if case.framework == "torch" else None)
    n_err = max(case.batches)
    err = median_rel_error(ev.numpy(ev.prepare(states["q"][:n_err], states["qdot"][:n_err])),
                           states["qddot"][:n_err])
    try:
        ops = ev.ops(ev.prepare(states["q"][:min(case.batches)], states["qdot"][:min(case.batches)]))
    except Exception:  # a count is a note's detail, never a reason to lose the row
        ops = None
    rows = []
    for b in case.batches:
        args = ev.prepare(states["q"][:b], states["qdot"][:b])
        if b != n_err:
            ev.run(args)  # warm-up (JAX: ahead-of-time compile for this shape); the error call warmed n_err
        paired = {}
        if jev is None:
            dt, threads = best_time(lambda a=args: ev.run(a), min_time=min_time), "default"  # JAX, NumPy
        else:
            jargs = jev.prepare(states["q"][:b], states["qdot"][:b])
            jev.run(jargs)  # JAX compiles for this shape
            dt, threads, jdt = _timed_paired(ev, args, jev, jargs, min_time)
            paired = {"jax_paired_samples_per_s": b / jdt}
        rows.append({"system": case.system, "model": case.model, "formulation": case.formulation,
                     "framework": case.framework, "mode": ev.mode, "threads": threads, "dtype": case.dtype,
                     "batch": int(b), "samples_per_s": b / dt, "error": err, "source": case.source, "ops": ops,
                     **paired, **case.extra})
    return rows
