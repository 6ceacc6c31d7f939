"""The parity table: one row per (model kind, formulation, task, loss, schedule, guard, mode, dtype).

Every model kind and formulation, every loss and schedule, the spike guard, restarts (scouted) and
vectorised members, each in float64 (`steps` at every step to `TOLERANCE["float64"]`) and float32 (a short
horizon, `F32_STEPS`, to `TOLERANCE["float32"]`), and the non-chaotic ones in float64 over `LONG_STEPS`.
`slow` rows run only under `-m slow` (and in the printed table). Widths are tiny: the JAX compile dominates, and rows that share a spec, loss, optimiser and clip
share one compiled step (`parity_kit._jax_step`), so the guarded LNN, the members and the scouted rows are
cut to the same shapes.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from lagbench.models import ModelSpec
from lagbench.replication.training.protocol import Data, Guard, Protocol, Scouting
from lagbench.replication.training.schedules import Anneal, Constant, OneCycle, StepDecay

# Relative differences allowed over the row's steps: loss, gradient norm, and the parameters as one vector
# (`parity_kit._params_rel`). float32: about 10x the largest measured over F32_STEPS steps (`python
# tests/replication/training/parity_kit.py`: 7.7e-7, 1.3e-5, 3.9e-5; the parameters' largest is an L1 loss whose
# signs cancel on a bias, which Adam turns into a step of 0 or about lr). "float32 chaotic": the LNN on the
# double pendulum, whose learned velocity Hessian is near-singular on some batches (gradient norms from 1e2
# to 1e6 from one batch to the next) and amplifies float32 rounding (measured: 3.3e-3, 6.9e-3, 1.1e-6); the
# step where its two frameworks part is `test_float32_parting`'s.
TOLERANCE = {"float64": {"loss": 1e-8, "grad_norm": 1e-8, "params": 1e-8},
             "float32": {"loss": 1e-5, "grad_norm": 1e-4, "params": 3e-4},
             "float32 chaotic": {"loss": 2e-2, "grad_norm": 5e-2, "params": 1e-5}}
F32_STEPS = 10
F64_STEPS = 20


@dataclass(frozen=True)
class Row:
    name: str
    spec: ModelSpec
    protocol: Protocol
    mode: str = "one"          # one | members | scouted
    seeds: tuple = (3,)
    slow: bool = False
    chaotic: bool = False      # float32 rounding amplified (TOLERANCE["float32 chaotic"])

    @property
    def tolerance(self) -> dict:
        dtype = self.protocol.dtype
        return TOLERANCE[dtype + " chaotic" if dtype == "float32" and self.chaotic else dtype]


DATA_FIELDS = ("n_train", "n_heldout", "resample", "system_params", "coords")


def _p(recipe, **kw) -> Protocol:
    """A protocol of short float64 runs; the `Data` fields given among the keywords."""
    kw = {"steps": F64_STEPS, "batch": 16, "n_train": 64, "n_heldout": 16, "dtype": "float64", "log_every": 1, **kw}
    data = Data(recipe, **{k: kw.pop(k) for k in DATA_FIELDS if k in kw})
    return Protocol(data=data, **kw)


def _s(kind, dof, **kw) -> ModelSpec:
    return ModelSpec(kind=kind, dof=dof, **{"hidden": (16, 16), "dtype": "float64", **kw})


DP = {"resample": True, "l2": 1e-6 / 512}                       # the double-pendulum protocol (l1, one-cycle)
REL = {"loss": "l1_gamma", "schedule": OneCycle(lr=1e-3, start=0.3)}                     # the relativistic protocol
LNN = _s("lnn", 2, angle_wrap=True)
C = {"chaotic": True}
GUARD = {"guard": Guard(clip=30.0, skip=1.0)}   # clip below the norms, skip at the median: both act often
GUARDED = _p("double_pendulum_iid", **DP, **GUARD, steps=40)
MEMBERS = GUARDED.replace(batch=8)
SCOUTED = GUARDED.replace(scouting=Scouting(count=4, steps=10, batch=8, schedule=OneCycle(lr=3e-3, start=GUARDED.schedule.start)), steps=20)
WAVE = {"system_params": (("n", 10), ("variant", "code")), "batch": 8, "schedule": OneCycle(lr=1e-3, start=0.3)}
ARM = {"task": "inverse_dynamics", "loss": "mse", "n_train": 400}

F64 = [
    Row("baseline_acc", _s("baseline", 1, activation="tanh", init="xavier"), _p("spring_iid", loss="mse")),
    # the early stop's closing anneal (a half cosine from step `begin`)
    Row("baseline_invdyn", _s("baseline", 2, activation="softplus", init="xavier", extra_inputs=2),
        _p("two_link_arm", **ARM, schedule=Anneal(lr=1e-3, final=1e-4, begin=5), l2=1e-5)),
    Row("baseline_dp", _s("baseline", 2, activation="relu", init="xavier", angle_wrap=True),
        _p("double_pendulum_iid", **DP)),
    Row("lnn_fast", LNN, _p("double_pendulum_iid", **DP), **C),
    # the side studies' LNNs: another activation and init (pytorch_default: biases not 0)
    Row("lnn_relu2", dataclasses.replace(LNN, activation="relu2", init="pytorch_default"),
        _p("double_pendulum_iid", **DP), **C),
    Row("lnn_paper", dataclasses.replace(LNN, formulation="paper"), _p("double_pendulum_iid", **DP), **C),
    Row("lnn_guarded", LNN, GUARDED, **C),
    # the learned Rayleigh dissipation, on a pendulum with friction; in float32 its untrained velocity Hessian
    # amplifies rounding as the double pendulum's does (measured over 10 steps: loss 5.0e-5, gradient norm 1.8e-4)
    Row("lnn_dissipation", _s("lnn", 1, dissipation=True), _p("pendulum_iid", system_params=(("friction", 0.3),),
                                                                loss="mse"), **C),
    Row("lnn_l1_gamma", _s("lnn", 1, extra_inputs=1, input_scale=(0.1, 1.0, 0.1)), _p("relativistic_iid", **REL)),
    Row("hnn_qp", _s("hnn", 1, activation="tanh", init="xavier"),
        _p("spring_iid", task="hamiltonian", coords="qp", loss="mse")),
    Row("hnn_qqdot", _s("hnn", 1, init="xavier", extra_inputs=1, input_scale=(0.1, 1.0, 0.1)),
        _p("relativistic_iid", task="hamiltonian", coords="qqdot", **REL)),
    Row("delan_inverse", _s("delan", 2, init="xavier"), _p("two_link_arm", **ARM, schedule=Constant(lr=1e-3), l2=1e-5)),
    Row("delan_forward", _s("delan", 2, init="xavier"), _p("charged_magnetic_iid")),
    Row("delan_dissipation", _s("delan", 2, init="xavier", dissipation=True),
        _p("two_link_arm", **ARM, schedule=Constant(lr=1e-3), l2=1e-5)),
    Row("hnn_dissipation", _s("hnn", 1, activation="tanh", init="xavier", dissipation=True),
        _p("pendulum_iid", task="hamiltonian", coords="qp", loss="mse", system_params=(("friction", 0.3),))),
    Row("lgn_banded", _s("lgn", 10, formulation="banded"),
        _p("wave_iid", **{**WAVE, "schedule": StepDecay(lr=1e-3, every=5, gamma=0.5)})),
    Row("lgn_dense", _s("lgn", 10, formulation="dense"), _p("wave_iid", **WAVE)),
    Row("lgn_paper", _s("lgn", 10, formulation="paper"), _p("wave_iid", **WAVE), slow=True),
    # K = 4 seeds as one program, each its own init and batches (what `Protocol.cohort` runs,
    # `replication.training.train.train_cohort`); the scouted row's scouts are the same program (its scout phase: 4 x 10
    # steps at batch 8), its continuation the guarded row's step
    Row("lnn_members", LNN, MEMBERS, mode="members", seeds=(3, 4, 5, 6), **C),
    Row("lnn_scouted", LNN, SCOUTED, mode="scouted", seeds=(1,), **C),
]


def in_float32(row: Row, steps: int = F32_STEPS, slow: bool | None = None) -> Row:
    p = row.protocol.replace(dtype="float32", steps=steps)
    if p.scouting:
        p = p.replace(**{"scouting.steps": min(p.scouting.steps, steps)})
    return dataclasses.replace(row, name=row.name + "_f32", spec=dataclasses.replace(row.spec, dtype="float32"),
                               protocol=p, slow=row.slow if slow is None else slow)


# float32 in the default run but for these (each a compile of its own, 5-15 s; their float64 rows show the
# mechanics): the members and scouted rows (the chaotic LNN again), the LGN's and the paper LNN's
F32_SLOW = ("lnn_members", "lnn_scouted", "lnn_relu2", "lnn_paper", "lgn_banded", "lgn_dense")
F32 = [in_float32(r, slow=r.slow or r.name in F32_SLOW) for r in F64]
# float64 over LONG_STEPS, slow: the kinds whose float64 runs do not part (the double-pendulum LNN's do,
# after about 100 steps: `test_float32_parting`)
LONG_STEPS = 200
LONG = [dataclasses.replace(r, name=r.name + "_long", protocol=r.protocol.replace(steps=LONG_STEPS), slow=True)
        for r in F64 if not (r.chaotic or r.slow)]
ROWS = F64 + F32 + LONG
BY_NAME = {r.name: r for r in ROWS}
