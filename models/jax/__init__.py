"""The JAX (equinox) models. Enables float64 (`jax_enable_x64`) on import; models use spec.dtype.

    build(spec, params) -> Model   (array leaves are exactly the params, cast to spec.dtype)
    to_params(model) -> dict[str, np.ndarray] in the `models.params` layout
"""
import jax

jax.config.update("jax_enable_x64", True)

from lagbench.models.jax.build import build, to_params  # noqa: E402

__all__ = ["build", "to_params"]
