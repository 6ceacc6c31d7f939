"""A user's model (`models.user`) trains in PyTorch only: the JAX registry holds this class so that every
kind has one, and building it says so."""
from __future__ import annotations


class UserModel:
    def __init__(self, params, spec):
        raise ValueError(f"--add-model {spec.factory}: a user's model is a torch.nn.Module and runs in PyTorch "
                         f"only (--frameworks torch)")
