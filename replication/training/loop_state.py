"""What the training loop (`loop.train_members`) works with, declared: the stepper and hook contracts, and
the one training state a snapshot serialises.

`MemberStepper`: one optimiser step of K members (K >= 1 models side by side as one program:
`train_jax.Members`, `train_torch.Members`, mirrors; a one-model `Stepper` through `loop._One`).
`Hook`: called after every step as `hook(k, stepper, info)`; True stops the run there. A hook with state
that must survive an interruption is also a `StatefulHook` (`snapshot_state`, `restore_snapshot`).

`TrainState`: per member its spike guard, log, failure, liveness and steps done; the next step, whether
the run has ended, its wall and step seconds. `snapshot(stepper, hooks, steps)` is the (meta, arrays) a
snapshot store writes (`snapshots.Snapshots`); `TrainState.restore(meta, arrays, stepper, hooks, guard)`
puts one back (the stepper's and hooks' state too); `narrow(state, members)` cuts a snapshot down to some
members (the scouts that go on after a cut, `scouting`).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np

from lagbench.replication.training.spike_guard import SpikeGuard


class MemberStepper(Protocol):
    """propose: each member's (loss (K,), global gradient norm (K,)) on its own batch, the update prepared
    not applied; bounds (K,): the guard's skip thresholds. commit: apply the prepared update of the members
    `taken`, each gradient scaled by its `scale` (the guard's clip factor). probe: the velocity-Hessian health
    columns per member (`hessian_probe`) on the batch last proposed. params: each member's parameters
    (`models.params` layout). state_arrays / load_state_arrays: parameters and optimiser state in a fixed
    order, for snapshots. mode (optional attribute): "jit", "compiled" or "eager"."""

    def propose(self, batches: list[dict], lr: float, bounds: np.ndarray) -> tuple[np.ndarray, np.ndarray]: ...

    def commit(self, taken: np.ndarray, scale: np.ndarray) -> None: ...

    def probe(self) -> list[dict | None] | None: ...

    def params(self) -> list[dict]: ...

    def state_arrays(self) -> list[np.ndarray]: ...

    def load_state_arrays(self, arrays: list[np.ndarray]) -> None: ...


class Hook(Protocol):
    """After step k: info = {loss (K,), lr, step_seconds, skipped_steps (K,), live (K,)}; True ends the run."""

    def __call__(self, k: int, stepper, info: dict) -> bool | None: ...


@runtime_checkable
class StatefulHook(Protocol):
    """A hook whose state travels in snapshots: snapshot_state() -> (JSON-able meta, {name: array})."""

    def snapshot_state(self) -> tuple[object, dict]: ...

    def restore_snapshot(self, meta, arrays: dict) -> None: ...


@dataclass
class TrainState:
    guards: list[SpikeGuard]
    logs: list[list[dict]]
    failures: list
    live: np.ndarray
    done: np.ndarray
    step: int = 0
    ended: bool = False
    wall: float = 0.0
    step_seconds: float = 0.0

    @classmethod
    def fresh(cls, members: int, guard) -> TrainState:
        return cls(guards=[SpikeGuard(guard) for _ in range(members)], logs=[[] for _ in range(members)],
                   failures=[None] * members, live=np.ones(members, bool), done=np.zeros(members, int))

    @property
    def members(self) -> int:
        return len(self.guards)

    def snapshot(self, stepper, hooks, steps: int) -> tuple[dict, dict]:
        """(meta, arrays): all the next step reads."""
        arrays = {f"stepper_{j:04d}": a for j, a in enumerate(stepper.state_arrays())}
        hook_meta = []
        for h, hook in enumerate(hooks):
            meta, extra = hook.snapshot_state() if isinstance(hook, StatefulHook) else (None, {})
            hook_meta.append(meta)
            arrays.update({f"hook{h}_{name}": a for name, a in extra.items()})
        meta = {"step": self.step, "steps": steps, "ended": self.ended, "wall_s": self.wall,
                "step_seconds": self.step_seconds, "members": self.members,
                "logs": self.logs, "failures": self.failures, "live": self.live, "done": self.done, "hooks": hook_meta,
                "guards": [{"history": list(g.history), "skipped": g.skipped} for g in self.guards]}
        return meta, arrays

    @classmethod
    def restore(cls, meta: dict, arrays: dict, stepper, hooks, guard) -> TrainState:
        """The state a snapshot holds, with the stepper's and the hooks' put back in place."""
        stepper.load_state_arrays([arrays[k] for k in sorted(arrays) if k.startswith("stepper_")])
        state = cls.fresh(len(meta["guards"]), guard)
        for g, saved in zip(state.guards, meta["guards"], strict=True):
            g.restore(saved["history"], saved["skipped"])
        state.logs = [list(rows) for rows in meta["logs"]]
        state.failures = list(meta["failures"])
        state.live[:], state.done[:] = meta["live"], meta["done"]
        for h, hook in enumerate(hooks[:len(meta["hooks"])]):   # none for a `narrow`ed state
            if isinstance(hook, StatefulHook):
                prefix = f"hook{h}_"
                hook.restore_snapshot(meta["hooks"][h], {k[len(prefix):]: a for k, a in arrays.items()
                                                         if k.startswith(prefix)})
        state.step, state.ended = int(meta["step"]), bool(meta["ended"])
        state.wall, state.step_seconds = float(meta["wall_s"]), float(meta["step_seconds"])
        return state


def fits(arrays: dict, stepper) -> bool:
    """Whether a snapshot's stepper arrays have the shapes of this stepper's state."""
    mine = [np.shape(a) for a in stepper.state_arrays()]
    return [np.shape(arrays[k]) for k in sorted(arrays) if k.startswith("stepper_")] == mine


def narrow(state, members) -> tuple[dict, dict]:
    """A snapshot's (meta, arrays) cut down to the stacked `members` (indices), to start a run of those
    alone from it (`start_state`): the stepper's arrays, logs, failures, guards, liveness and steps done of
    those members; the hooks' state is left behind (their owner carries what it needs)."""
    meta, arrays = state
    idx = np.asarray(members, int)
    each = {name: [meta[name][i] for i in idx] for name in ("logs", "failures", "guards")}
    return ({**meta, **each, "members": len(idx), "ended": False, "hooks": [],
             "live": np.asarray(meta["live"])[idx], "done": np.asarray(meta["done"])[idx]},
            {k: np.asarray(a)[idx] for k, a in arrays.items() if k.startswith("stepper_")})
