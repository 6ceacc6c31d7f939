"""build(spec, params) -> the PyTorch model of spec.kind; to_params(model) -> the NumPy layout.
build_stacked(spec, params_list) -> one model of K stacked members (`models.torch.base.Model`), for the
kinds whose class `stacks(spec)`; to_params gives its (K, ...) arrays. compiles(spec): whether its training
loss may run under torch.compile.

CLASSES (kind -> class) is read off `models.spec.CAPABILITIES`: kind k's class is the one named
`CAPABILITIES[k].model_class` in `models/torch/<k>.py`, imported by name (the mirror of `models.jax.build`).
"""
from __future__ import annotations

import importlib

import numpy as np

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


def stacks(spec: ModelSpec) -> bool:
    """Whether spec's model takes stacked members (`build_stacked`)."""
    return CLASSES[spec.kind].stacks(spec)


def compiles(spec: ModelSpec) -> bool:
    """Whether a training loss of spec's model may run under torch.compile (`Model.compiles`)."""
    return CLASSES[spec.kind].compiles(spec)


def build_stacked(spec: ModelSpec, params_list: list[dict]):
    """One nn.Module holding K = len(params_list) models of spec, each parameter stacked on a leading axis."""
    cls = CLASSES[spec.kind]
    if not cls.stacks(spec):
        raise ValueError(f"a {spec.kind} model with this spec does not take stacked members")
    for params in params_list:
        check_params(spec, params)
    return cls(spec, {k: np.stack([p[k] for p in params_list]) for k in params_list[0]}, members=len(params_list))
