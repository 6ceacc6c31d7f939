"""The systems' JAX code (SymPy-generated right-hand sides, the data generators) runs its tests with JAX's
strict numerics: NumPy rank promotion raises (every broadcast written out) and dtype promotion is strict
(no implicit float32/float64 mixing). The models' code (`models/jax`) broadcasts its parameters over the
leading batch axes by design, so the tests of code that runs a model keep JAX's defaults."""
import jax
import pytest


@pytest.fixture(autouse=True)
def strict_jax_numerics():
    with jax.numpy_rank_promotion("raise"), jax.numpy_dtype_promotion("strict"):
        yield

