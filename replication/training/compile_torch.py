"""torch.compile of a PyTorch training loss: when it is used, where its generated code lives, and the eager
fallback. JAX needs none of this: its step is always jit-compiled.

`compiled_loss(loss_fn, spec, protocol, members=1) -> CompiledLoss | loss_fn`: the loss as `train_torch.Stepper`
and `Members` call it, `loss_fn(model, batch)`. `step_mode(loss) -> "compiled" | "eager" | "eager (...)"`: what
a training phase ran, recorded in its outcome (`TrainOutcome.step_mode`). `like(spec, protocol, members=1)`: a
context in which every phase compiles as a phase of `protocol` would; `setting_as(value)`: one in which the
setting is `value` (the speed study's members stage times PyTorch both ways).

When (`LAGBENCH_TORCH_COMPILE`, read for each training phase):
  auto (default): where the model's loss is plain tensor ops and compiling pays (`lagbench.models.torch.compiles`:
        the fast LNN; not the feed-forward baseline, whose step is its matrix products) and the phase trains
        at least COMPILE_MIN_SAMPLES samples (steps x batch x members), so that the capture (about 26 s for
        the double pendulum's 3 x 128 LNN on a cold cache, 12 s warm) is paid back: the double pendulum's
        scouts, kept scouts and continuation, claims 6 and 7's cohorts, claim 3's continuations; not the
        relativistic scouts (200 steps) or the tests;
  on:   wherever the kind allows, however short (the tests);
  off:  never.
The whole loss is captured (fullgraph): in the models, `lagbench.models.torch.export_paths.compiling` picks the
branch-free fallback solve and the plain softplus. Gradients are autograd's of the same maths, so a compiled
phase's numbers equal the eager ones up to rounding (`tests/replication/training/test_compile_torch.py`).
A capture or build that fails (no C++ compiler, an op dynamo cannot take) is logged, and the phase goes on
eager from the same state; its mode says so.

Measured, `full`'s double-pendulum LNN (3 x 128, softplus), one thread, interleaved rounds on an idle
2-core machine: the continuation's step at batch 256 7.8 ms compiled against 12.4 ms eager (JAX's jit
8.6 ms); 16 stacked scouts at batch 32 17-20 ms against 28 ms.

Where: inductor's cache of generated C++ and its shared objects is `$LAGBENCH_CACHE/torchinductor`
(`lagbench.models.torch.inductor_cache`), so that workers and later runs reuse a capture; where that folder is not
this user's own, nothing is compiled.
"""
from __future__ import annotations

import contextlib
import logging
import os

import torch

import lagbench.models.torch
from lagbench.models.torch import inductor_cache

log = logging.getLogger("lagbench")

ENV = "LAGBENCH_TORCH_COMPILE"
SETTINGS = ("auto", "on", "off")
COMPILE_MIN_SAMPLES = 2_000_000


@contextlib.contextmanager
def like(spec, protocol, members: int = 1):
    """Within it, every phase compiles exactly when a phase of `protocol` with `members` would (the duration
    estimate's short probes of a long phase: `replication.run.estimate`)."""
    with setting_as("on" if wanted(spec, protocol, members) else "off"):
        yield


@contextlib.contextmanager
def setting_as(value: str):
    """Within it, `LAGBENCH_TORCH_COMPILE` is `value` (one of SETTINGS); put back after."""
    before = os.environ.get(ENV)
    os.environ[ENV] = _valid(value)
    try:
        yield
    finally:
        if before is None:
            os.environ.pop(ENV, None)
        else:
            os.environ[ENV] = before


def setting() -> str:
    return _valid(os.environ.get(ENV, "auto").strip().lower() or "auto")


def _valid(value: str) -> str:
    if value not in SETTINGS:
        raise ValueError(f"{ENV}={value!r}; valid: {', '.join(SETTINGS)}")
    return value


def wanted(spec, protocol, members: int = 1) -> bool:
    """Whether the loss of this phase (`members` models side by side) should run under torch.compile."""
    how = setting()
    if how == "off" or not lagbench.models.torch.compiles(spec):
        return False
    return how == "on" or protocol.steps * protocol.batch * members >= COMPILE_MIN_SAMPLES


class CompiledLoss:
    """`loss_fn` under torch.compile (fullgraph); the first failure turns it to `loss_fn` for good."""

    def __init__(self, loss_fn):
        torch._dynamo.reset()   # one training phase at a time: earlier phases' captures are not called again
        self.eager, self.mode = loss_fn, "compiled"
        self.fn = torch.compile(loss_fn, fullgraph=True, dynamic=False)

    def __call__(self, model, batch):
        if self.fn is not self.eager:
            try:
                return self.fn(model, batch)
            except Exception as exc:   # a capture or build failure: nothing was updated, go on eager
                reason = f"{type(exc).__name__}: {str(exc).splitlines()[0][:160] if str(exc) else ''}"
                log.warning("torch.compile failed, training eager: %s", reason)
                self.fn, self.mode = self.eager, f"eager (torch.compile failed: {type(exc).__name__})"
        return self.eager(model, batch)


def compiler() -> str | None:
    """The C++ compiler inductor would build with on the CPU ($CXX, else c++, g++, clang++ on PATH), or None."""
    import shutil

    found = [shutil.which(c) for c in (os.environ.get("CXX", ""), "c++", "g++", "clang++") if c]
    return next((c for c in found if c), None)


_WARNED: set = set()


def compiled_loss(loss_fn, spec, protocol, members: int = 1):
    """loss_fn, compiled where `wanted`, inductor has a private cache folder and, for the CPU, a C++ compiler
    is on PATH (without one: eager, with one warning per process saying so)."""
    if not (wanted(spec, protocol, members) and inductor_cache.private()):
        return loss_fn
    if torch.get_default_device().type == "cpu" and compiler() is None:
        if "compiler" not in _WARNED:
            _WARNED.add("compiler")
            log.warning("torch.compile needs a C++ compiler (set CXX or install g++): PyTorch trains eagerly")
        return loss_fn
    return CompiledLoss(loss_fn)


def step_mode(loss) -> str:
    return getattr(loss, "mode", "eager")
