"""pytest-benchmark cases for the speed study (marked `bench`, excluded from the default run).

Run: `pytest -m bench --benchmark-enable --benchmark-only tests/speedstudy` (the tox `bench` env). They time,
never assert a time:
- q-double-dot throughput per model x framework x formulation, batch 4096, float32, the paper's MLP
  (3 x 600 softplus), on the double pendulum (d = 2) and the pendulum chain (d = 8, 16): LNN paper/fast,
  HNN (on (q, qdot)), DeLaN, baseline, and the SymPy ground truth;
- the LGN dense vs banded path on a periodic grid, n = 16 .. 4096 (dense only up to 1024: beyond, one
  evaluation takes minutes on a CPU).
Each benchmark's `extra_info` holds the samples per call, so samples/s = batch / mean time.
"""
import numpy as np
import pytest

from lagbench import systems
from lagbench.models import init_params
from lagbench.speedstudy.evaluators import make_evaluator
from lagbench.speedstudy.inference import model_spec

pytestmark = pytest.mark.bench

BATCH = 4096
HIDDEN = (600, 600, 600)
SYSTEMS = {2: ("double_pendulum", {}), 8: ("pendulum_chain", {"n": 8}), 16: ("pendulum_chain", {"n": 16})}
MODELS = [("lnn", "paper"), ("lnn", "fast"), ("hnn", "-"), ("delan", "-"), ("baseline", "-"), ("truth", "-")]
LGN_N = (16, 64, 256, 1024, 4096)
DENSE_MAX_N = 1024


def _states(dof, batch, seed=0):
    rng = np.random.default_rng(seed)
    return rng.uniform(-np.pi, np.pi, (batch, dof)), rng.uniform(-1.0, 1.0, (batch, dof))


def _bench(benchmark, ev, q, qd, batch, rounds):
    args = ev.prepare(q, qd)
    ev.run(args)  # warm-up / compile
    benchmark.extra_info["samples_per_call"] = batch
    benchmark.pedantic(ev.run, args=(args,), rounds=rounds, iterations=1)


@pytest.mark.parametrize("framework", ["jax", "torch"])
@pytest.mark.parametrize("kind,formulation", MODELS, ids=[f"{k}-{f}" for k, f in MODELS])
@pytest.mark.parametrize("dof", sorted(SYSTEMS))
def test_qddot_throughput(benchmark, dof, kind, formulation, framework):
    name, kw = SYSTEMS[dof]
    if kind == "truth":
        ev = make_evaluator(framework, kind="truth", dtype="float32", system=systems.get(name, **kw))
    else:
        spec = model_spec(kind, formulation, dof, HIDDEN, "float32")
        ev = make_evaluator(framework, spec, init_params(spec, seed=0))
    q, qd = _states(dof, BATCH)
    heavy = kind == "lnn" and dof >= 8
    _bench(benchmark, ev, q, qd, BATCH, rounds=2 if heavy else 5)


@pytest.mark.parametrize("framework", ["jax", "torch"])
@pytest.mark.parametrize("formulation", ["dense", "banded"])
@pytest.mark.parametrize("n", LGN_N)
def test_lgn_grid(benchmark, n, formulation, framework):
    if formulation == "dense" and n > DENSE_MAX_N:
        pytest.skip(f"dense LGN above n = {DENSE_MAX_N}: minutes per evaluation on a CPU")
    spec = model_spec("lgn", formulation, n, (64, 64, 64), "float32", lgn_radius=1)
    ev = make_evaluator(framework, spec, init_params(spec, seed=0))
    batch = max(1, 1024 // n)
    q, qd = _states(n, batch)
    _bench(benchmark, ev, q, qd, batch, rounds=3)
