"""build(spec, params) -> the PyTorch model of spec.kind; to_params(model) -> the NumPy layout.

CLASSES (kind -> class) is read off `models.spec.CAPABILITIES`: kind k's class is the one named
`CAPABILITIES[k].model_class` in `models/torch/<k>.py`, imported by name (the mirror of `models.jax.build`).
"""
from __future__ import annotations

import importlib

from models.params import check_params
from models.spec import CAPABILITIES, ModelSpec

CLASSES = {kind: getattr(importlib.import_module(f"models.torch.{kind}"), cap.model_class)
           for kind, cap in CAPABILITIES.items()}


def build(spec: ModelSpec, params: dict):
    """An nn.Module of class CLASSES[spec.kind] whose parameters are params cast to spec.dtype."""
    check_params(spec, params)
    return CLASSES[spec.kind](spec, params)


def to_params(model) -> dict:
    """{key: np.ndarray} with the same keys and shapes as `init_params` gives."""
    return {k: v.detach().cpu().numpy().copy() for k, v in model.named_parameters()}
