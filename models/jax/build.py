"""build(spec, params) -> the JAX model of spec.kind; to_params(model) -> the NumPy layout.

CLASSES (kind -> class) is read off `models.spec.CAPABILITIES`: kind k's class is the one named
`CAPABILITIES[k].model_class` in `models/jax/<k>.py`, imported by name.
"""
from __future__ import annotations

import importlib

import jax.numpy as jnp
import numpy as np

from lagbench.models.params import check_params
from lagbench.models.spec import CAPABILITIES, USER_KIND, ModelSpec

CLASSES = {kind: getattr(importlib.import_module(f"lagbench.models.jax.{kind}"), cap.model_class)
           for kind, cap in CAPABILITIES.items()}


def model_class(kind: str):
    """CLASSES[kind], or a user's model (`models.user`), imported when one is built."""
    if kind == USER_KIND:
        return importlib.import_module("lagbench.models.jax.user").UserModel
    return CLASSES[kind]


def build(spec: ModelSpec, params: dict):
    """An equinox Module of class CLASSES[spec.kind] holding params cast to spec.dtype."""
    check_params(spec, params)
    arrays = {k: jnp.asarray(np.asarray(v), dtype=spec.dtype) for k, v in params.items()}
    return model_class(spec.kind)(arrays, spec)


def to_params(model) -> dict:
    """{key: np.ndarray} with the same keys and shapes as `init_params` gives."""
    return {k: np.asarray(v) for k, v in model.params.items()}
