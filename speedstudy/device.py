"""Where the speed study runs: the CPU (default) or one CUDA GPU (`lagbench bench --gpu`).

`gpu_session()` (a context manager) checks that both frameworks see a GPU (else NoGPUError naming what
is missing), makes CUDA PyTorch's default device (so models, states and the constants the models create
land on it) and sets both frameworks to full float32 matrix products: JAX on a GPU defaults to TF32 for
float32 dots, PyTorch does not; "highest" in JAX and `allow_tf32 = False` in PyTorch make the two do the
same arithmetic, which the error column checks. It restores every setting on exit.
`on_gpu()`: inside a gpu_session. `sync()`: waits for PyTorch's queued GPU work (a no-op on the CPU), so
that a timed PyTorch call blocks until its result is ready, as `jax.block_until_ready` does for JAX.
`to_numpy(t)`: a PyTorch tensor as NumPy, from any device.
`settings()`: what machine.json records of the device.
"""
from __future__ import annotations

from contextlib import contextmanager

import jax
import torch

_STATE = {"gpu": False}


class NoGPUError(RuntimeError):
    """A GPU run was asked for where a framework sees no GPU."""


def on_gpu() -> bool:
    return _STATE["gpu"]


def sync() -> None:
    if _STATE["gpu"]:
        torch.cuda.synchronize()


def to_numpy(t):
    return t.detach().cpu().numpy()


def _check() -> None:
    missing = []
    if not torch.cuda.is_available():
        missing.append(f"PyTorch {torch.__version__} sees no CUDA device")
    if jax.default_backend() != "gpu":
        missing.append(f"JAX {jax.__version__}'s default backend is {jax.default_backend()!r}, not 'gpu'")
    if missing:
        raise NoGPUError("--gpu needs a CUDA GPU visible to both frameworks: " + "; ".join(missing))


@contextmanager
def gpu_session():
    _check()
    old = (torch.get_default_device(), torch.backends.cuda.matmul.allow_tf32, torch.backends.cudnn.allow_tf32,
           jax.config.jax_default_matmul_precision)
    torch.set_default_device("cuda")
    torch.backends.cuda.matmul.allow_tf32 = False
    torch.backends.cudnn.allow_tf32 = False
    jax.config.update("jax_default_matmul_precision", "highest")
    _STATE["gpu"] = True
    try:
        yield
    finally:
        _STATE["gpu"] = False
        torch.set_default_device(old[0])
        torch.backends.cuda.matmul.allow_tf32, torch.backends.cudnn.allow_tf32 = old[1], old[2]
        jax.config.update("jax_default_matmul_precision", old[3])


def settings() -> dict:
    if not _STATE["gpu"]:
        return {"device": "cpu"}
    p = torch.cuda.get_device_properties(0)
    return {"device": "cuda", "torch_gpu": p.name, "torch_gpu_memory_gib": round(p.total_memory / 2**30, 1),
            "torch_cuda": torch.version.cuda, "jax_devices": [str(d) for d in jax.devices()],
            "float32_matmul": "full float32 in both (JAX precision 'highest', PyTorch allow_tf32 False)"}
