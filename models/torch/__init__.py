"""The PyTorch (torch.func) models, mirroring `models.jax`.

    build(spec, params) -> Model   (nn.Module; its nn.Parameters are exactly the params, spec.dtype)
    to_params(model) -> dict[str, np.ndarray] in the `models.params` layout
"""
from models.torch.build import build, to_params

__all__ = ["build", "to_params"]
