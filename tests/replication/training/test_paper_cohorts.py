"""Every `paper` protocol trains its seeds as one program (`training.train.train_cohort`, what a GPU run packs:
`replication.run.gpu_cohorts`) with each seed's numbers those of its run alone, in JAX and in PyTorch.

Each case is a `paper` model as the run plans it (`runner.plan`: the claim's protocol with its tuned overrides,
the model's spec), shrunk: every hidden width `WIDTH`, `STEPS` steps of at most `BATCH` samples from a pool of
three batches, float64. Cases are the distinct step programs (the spec but its init and widths; the task,
loss, data recipe and coordinates): the first program of each model kind runs by default, the others (each
claim's own, the activation study's other activations, the relativistic variants, ...) under `-m slow`. A model
that trains nothing, or whose protocol cannot be packed (`gpu_cohorts.blocker`), is listed below with its
reason; `test_every_paper_model_is_a_case_or_listed` fails for a `paper` model that is neither.
"""
import dataclasses
import json

import numpy as np
import pytest

from lagbench.replication.claims import CLAIMS
from lagbench.replication.claims.resolved import resolved
from lagbench.replication.run.gpu_cohorts import blocker
from lagbench.replication.run.runner import plan
from lagbench.replication.training import train as training

WIDTH, STEPS, BATCH = 8, 3, 4
SEEDS = (0, 1, 2)
# "claim/model" -> why it is no case
NOT_TRAINED = {
    "appendix_b/lnn_exact_paper": "an exact Lagrangian, evaluated without training",
    "appendix_b/lnn_exact_fast": "an exact Lagrangian, evaluated without training",
    "delan_online/delan": "learns inside its evaluation (online control), in no training program",
    "delan_online/ff": "learns inside its evaluation (online control), in no training program",
}
NOT_PACKABLE: dict = {}   # "claim/model" -> `blocker`'s reason; no `paper` protocol has restarts, early stop or a cohort


def _program(u) -> str:
    """What makes a step program differ: the spec but its init and widths; the task, loss, recipe, coordinates."""
    spec = {k: v for k, v in u.spec().to_dict().items() if k not in ("init", "hidden", "dtype")}
    p = u.protocol()
    return json.dumps([spec, p.task, p.loss, p.data.recipe, p.data.coords], sort_keys=True, default=str)


def _cases():
    """(name, unit, default): one unit per distinct program; `default` for the first of a model kind."""
    cases, kinds = {}, set()
    for u in plan("paper", frameworks=("jax",), seeds=1):
        if not u.entry.train or blocker(u.protocol()):
            continue
        first = u.spec().kind not in kinds
        kinds.add(u.spec().kind)
        name = f"{u.claim.id}/{u.entry.label}"
        key = _program(u)
        if key not in cases:
            cases[key] = (name, u, first)
        elif first and not cases[key][2]:
            cases[key] = (cases[key][0], cases[key][1], True)
    return list(cases.values())


CASES = _cases()


def _small(u):
    spec, p = u.spec(), u.protocol()
    batch = min(p.batch, BATCH)
    small = p.replace(steps=STEPS, batch=batch, log_every=1, dtype="float64",
                      **{"data.n_train": 3 * batch, "data.n_heldout": 4})
    return dataclasses.replace(spec, hidden=(WIDTH,) * len(spec.hidden), dtype="float64"), small


def test_every_paper_model_is_a_case_or_listed():
    programs = {_program(u): d for _, u, d in CASES}
    seen, kinds = set(), {}
    for cid, claim in CLAIMS.items():
        for m in resolved(claim, "paper").models:
            name = f"{cid}/{m.label}"
            seen.add(name)
            if not m.train:
                assert name in NOT_TRAINED, f"{name} trains nothing under paper: list it in NOT_TRAINED"
                continue
            assert name not in NOT_TRAINED, f"{name} trains under paper: remove it from NOT_TRAINED"
            reason = blocker(m.protocol)
            if reason:
                assert NOT_PACKABLE.get(name) == reason, f"{name} cannot be packed ({reason}): list it in NOT_PACKABLE"
                continue
            assert name not in NOT_PACKABLE, f"{name} can be packed: remove it from NOT_PACKABLE"
            (u,) = plan("paper", claims=[cid], frameworks=("jax",), models=[m.label], seeds=1)
            assert _program(u) in programs, f"{name}: its step program is no case"
            kinds[u.spec().kind] = kinds.get(u.spec().kind, False) or programs[_program(u)]
    assert all(kinds.values()), f"a model kind with no case by default: {kinds}"
    assert set(NOT_TRAINED) | set(NOT_PACKABLE) <= seen, "a listed model no claim runs under paper"


@pytest.mark.parametrize("fw", ["jax", "torch"])
@pytest.mark.parametrize("name, unit", [pytest.param(n, u, id=n, marks=() if d else pytest.mark.slow)
                                        for n, u, d in CASES])
def test_a_paper_cohort_trains_each_seed_as_alone(name, unit, fw):
    spec, protocol = _small(unit)
    together = training.train_cohort(fw, spec, protocol, list(SEEDS))
    assert [o.cohort for o in together] == [{"seeds": list(SEEDS)}] * len(SEEDS)
    for seed, b in zip(SEEDS, together, strict=True):
        a = training.run_training(fw, spec, protocol, seed)
        assert a.failure is None and b.failure is None and len(a.log) == len(b.log) == STEPS
        for ra, rb in zip(a.log, b.log, strict=True):
            assert ra["step"] == rb["step"] and ra["lr"] == rb["lr"]
            for k in ("loss", "grad_norm"):
                np.testing.assert_allclose(rb[k], ra[k], rtol=1e-10, err_msg=f"{name} seed {seed} step {ra['step']} {k}")
        for k in a.params:
            np.testing.assert_allclose(b.params[k], a.params[k], rtol=1e-9, atol=1e-12, err_msg=f"{name} seed {seed} {k}")
    a, b = together[0].params, together[1].params   # each seed its own init and batches: other weights
    assert any(not np.allclose(a[k], b[k]) for k in a)
