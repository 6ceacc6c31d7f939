"""build(spec, params) -> the JAX model of spec.kind; to_params(model) -> the NumPy layout."""
from __future__ import annotations

import jax.numpy as jnp
import numpy as np

from models.jax.baseline import Baseline
from models.jax.delan import DeLaN
from models.jax.hnn import HNN
from models.jax.lgn import LGN
from models.jax.lnn import LNN
from models.params import check_params
from models.spec import ModelSpec

CLASSES = {"baseline": Baseline, "lnn": LNN, "hnn": HNN, "delan": DeLaN, "lgn": LGN}


def build(spec: ModelSpec, params: dict):
    """An equinox Module of class CLASSES[spec.kind] holding params cast to spec.dtype."""
    check_params(spec, params)
    arrays = {k: jnp.asarray(np.asarray(v), dtype=spec.dtype) for k, v in params.items()}
    return CLASSES[spec.kind](arrays, spec)


def to_params(model) -> dict:
    """{key: np.ndarray} with the same keys and shapes as `init_params` gives."""
    return {k: np.asarray(v) for k, v in model.params.items()}
