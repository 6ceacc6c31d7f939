"""Where models train and are evaluated: `--device cpu | gpu | auto` (`run`, `fit`, `evaluate`, `train-target`).

`resolve(request, framework)` -> "cpu" | "gpu": auto takes the framework's GPU where it sees one (JAX's
default, and now PyTorch's too), else the CPU; gpu where the framework sees none raises `DeviceError`, one
line that names the framework and what it sees, before anything is written. `check(request, frameworks)`
resolves every framework of a command up front (the CLI's early check). `placed(framework, device)`: a
context in which the framework's training computes on that device: PyTorch's default device (so models,
batches, optimiser state and the constants the models make land on it) or JAX's default device, with
float32 matrix products at full precision on a GPU (JAX's default there is TF32-like; PyTorch's
`allow_tf32` off) unless `LAGBENCH_TF32=1`. Training data and targets are made in NumPy on the CPU; an
evaluation runs its model on the device (its JAX ground-truth integrations, float64, where JAX computes). `describe(framework, device)`:
what result files record (the device, its name and driver).

The request travels to worker processes and Ray tasks in the environment variable `LAGBENCH_DEVICE`
(`request()` reads it; default auto). It is a run option, not part of a training's key: a model trained on
either device is the same protocol, and its record says where it ran.
"""
from __future__ import annotations

import os
from contextlib import contextmanager

CHOICES = ("auto", "cpu", "gpu")
HELP = ("where the models train and are evaluated: auto (a GPU where the framework sees one, else the CPU), "
        "cpu, or gpu (an error if a framework sees none); training data are made in NumPy on the CPU "
        "(default: auto)")
ENV = "LAGBENCH_DEVICE"
TF32_ENV = "LAGBENCH_TF32"


class DeviceError(ValueError):
    """A GPU was asked for where a framework sees none, or the request is not a device."""


def request() -> str:
    """The device asked for, from LAGBENCH_DEVICE (default auto)."""
    value = os.environ.get(ENV, "auto").strip().lower() or "auto"
    if value not in CHOICES:
        raise DeviceError(f"{ENV}={value!r} is not a device; valid: {', '.join(CHOICES)}")
    return value


def _torch_gpu() -> tuple[bool, str]:
    import torch

    if torch.cuda.is_available():
        return True, torch.cuda.get_device_name(0)
    return False, f"PyTorch {torch.__version__} sees no CUDA device (a CPU build, or no driver)"


def _jax_gpu():
    import jax

    try:
        devs = jax.devices("gpu")
    except RuntimeError:
        devs = []
    if devs:
        return True, devs[0]
    return False, f"JAX {jax.__version__} has no GPU backend (install the CUDA plugin: docs/gpu.md)"


def gpu_seen(framework: str) -> tuple[bool, object]:
    if framework == "torch":
        return _torch_gpu()
    if framework == "jax":
        return _jax_gpu()
    raise DeviceError(f"unknown framework {framework!r}; valid: jax, torch")


def resolve(req: str, framework: str) -> str:
    if req not in CHOICES:
        raise DeviceError(f"--device {req!r} is not a device; valid: {', '.join(CHOICES)}")
    if req == "cpu":
        return "cpu"
    seen, what = gpu_seen(framework)
    if seen:
        return "gpu"
    if req == "gpu":
        raise DeviceError(f"--device gpu: {what}; use --device cpu or auto")
    return "cpu"


def check(req: str, frameworks) -> dict:
    """{framework: resolved device} for every framework of a command; one DeviceError naming every framework
    that sees no GPU where one was asked for."""
    if req not in CHOICES:
        raise DeviceError(f"--device {req!r} is not a device; valid: {', '.join(CHOICES)}")
    seen = {fw: gpu_seen(fw) for fw in frameworks} if req != "cpu" else {}   # each framework asked once
    missing = [what for ok, what in seen.values() if not ok]
    if req == "gpu" and missing:
        raise DeviceError(f"--device gpu: {'; '.join(missing)}; use --device cpu or auto")
    return {fw: "gpu" if seen.get(fw, (False,))[0] else "cpu" for fw in frameworks}


def apply(req: str, frameworks) -> dict:
    """A command's `--device`: every framework resolved first (DeviceError before anything is written), then
    the request set in LAGBENCH_DEVICE for this process, its workers and Ray tasks."""
    where = check(req, [fw for fw in frameworks if fw in ("jax", "torch")])   # others: the command's own error
    os.environ[ENV] = req
    return where


def _full_float32() -> bool:
    return os.environ.get(TF32_ENV, "") != "1"


@contextmanager
def placed(framework: str, device: str):
    """Compute this framework's training on `device` ("cpu" | "gpu") inside the block."""
    if framework == "torch":
        import torch

        old = (torch.get_default_device(), torch.backends.cuda.matmul.allow_tf32, torch.backends.cudnn.allow_tf32)
        if device == "gpu":
            torch.set_default_device("cuda")
            if _full_float32():
                torch.backends.cuda.matmul.allow_tf32 = False
                torch.backends.cudnn.allow_tf32 = False
        try:
            yield
        finally:
            torch.set_default_device(old[0])
            torch.backends.cuda.matmul.allow_tf32, torch.backends.cudnn.allow_tf32 = old[1], old[2]
        return
    import jax

    target = gpu_seen("jax")[1] if device == "gpu" else jax.devices("cpu")[0]
    old_precision = jax.config.jax_default_matmul_precision
    if device == "gpu" and _full_float32():
        jax.config.update("jax_default_matmul_precision", "highest")
    try:
        with jax.default_device(target):
            yield
    finally:
        jax.config.update("jax_default_matmul_precision", old_precision)


def _nvidia_driver() -> str | None:
    """The NVIDIA kernel driver's version line, where the machine has one."""
    try:
        with open("/proc/driver/nvidia/version") as f:
            return f.readline().strip() or None
    except OSError:
        return None


def describe(framework: str, device: str) -> dict:
    """What a result records of where its training computed."""
    out = {"device": device, "name": "cpu", "driver": None,
           "float32_matmul": "full float32" if device == "cpu" or _full_float32() else "TF32 allowed"}
    if device != "gpu":
        return out
    if framework == "torch":
        import torch

        out.update(name=torch.cuda.get_device_name(0), runtime=f"CUDA {torch.version.cuda}")
    else:
        import jax

        dev = gpu_seen("jax")[1]
        out.update(name=getattr(dev, "device_kind", str(dev)), runtime=f"jaxlib {jax.__version__}")
    out["driver"] = _nvidia_driver()
    return out
