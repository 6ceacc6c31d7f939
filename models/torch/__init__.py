"""The PyTorch (torch.func) models, mirroring `models.jax`.

    build(spec, params) -> Model   (nn.Module; its nn.Parameters are exactly the params, spec.dtype)
    to_params(model) -> dict[str, np.ndarray] in the `models.params` layout
    build_stacked(spec, params_list) -> one Model of K stacked members, for the specs where stacks(spec)
    compiles(spec) -> whether a training loss of spec's model may run under torch.compile

Importing it flushes subnormal floats to zero in PyTorch, as XLA does (`models.torch.subnormals`), before
anything here computes.
"""
from lagbench.models.torch import subnormals
from lagbench.models.torch.build import build, build_stacked, compiles, stacks, to_params

subnormals.flush()

__all__ = ["build", "build_stacked", "compiles", "stacks", "to_params"]
