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

from lagbench.models.params import check_params
from lagbench.models.spec import CAPABILITIES, USER_KIND, ModelSpec

CLASSES = {kind: getattr(importlib.import_module(f"lagbench.models.torch.{kind}"), cap.model_class)
           for kind, cap in CAPABILITIES.items()}


def model_class(kind: str):
    """CLASSES[kind], or a user's model (`models.user`), imported when one is built."""
    if kind == USER_KIND:
        return importlib.import_module("lagbench.models.torch.user").UserModel
    return CLASSES[kind]


def build(spec: ModelSpec, params: dict):
    """An nn.Module of class CLASSES[spec.kind] whose parameters are params cast to spec.dtype."""
    check_params(spec, params)
    return model_class(spec.kind)(spec, params)


def to_params(model) -> dict:
    """{key: np.ndarray} with the same keys and shapes as `init_params` gives."""
    return {k: v.detach().cpu().numpy().copy() for k, v in model.named_parameters()}


def stacks(spec: ModelSpec) -> bool:
    """Whether spec's model takes stacked members (`build_stacked`)."""
    return model_class(spec.kind).stacks(spec)


def compiles(spec: ModelSpec) -> bool:
    """Whether a training loss of spec's model may run under torch.compile (`Model.compiles`)."""
    return model_class(spec.kind).compiles(spec)


def build_stacked(spec: ModelSpec, params_list: list[dict]):
    """One nn.Module holding K = len(params_list) models of spec, each parameter stacked on a leading axis."""
    cls = model_class(spec.kind)
    if not cls.stacks(spec):
        raise ValueError(f"a {spec.kind} model with this spec does not take stacked members")
    for params in params_list:
        check_params(spec, params)
    return cls(spec, {k: np.stack([p[k] for p in params_list]) for k in params_list[0]}, members=len(params_list))
