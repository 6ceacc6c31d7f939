"""The neutral spec, the parameter layout, the initialisation, and clear errors on bad input."""
import jax.numpy as jnp
import numpy as np
import pytest
import torch

import lagbench.models.jax
import lagbench.models.torch
from lagbench.models import ACTIVATIONS, INITS, KINDS, ModelSpec, init_params, param_shapes


@pytest.mark.parametrize("bad, match", [
    ({"kind": "cnn"}, "unknown kind 'cnn'; valid: baseline, lnn"),
    ({"activation": "gelu"}, "unknown activation 'gelu'; valid: softplus"),
    ({"init": "orthogonal"}, "unknown init 'orthogonal'; valid: cranmer2020"),
    ({"formulation": "sparse"}, "unknown lnn formulation 'sparse'; valid: fast, paper"),
    ({"formulation": "banded"}, "unknown lnn formulation 'banded'"),
    ({"dof": 0}, "dof must be an integer >= 1, got 0"),
    ({"dof": 2.0}, "dof must be an integer >= 1, got 2.0"),
    ({"hidden": (8.0,)}, r"hidden must be a non-empty sequence of integers >= 1, got \(8.0,\)"),
    ({"hidden": ()}, "hidden must be a non-empty"),
    ({"hidden": (32, -1)}, "hidden must be a non-empty"),
    ({"dtype": "float16"}, "unknown dtype"),
    ({"input_scale": (1.0, 2.0)}, "input_scale needs 4 entries"),
])
def test_spec_rejects_bad_values(bad, match):
    kw = {"kind": "lnn", "dof": 2, "hidden": (32,)} | bad
    with pytest.raises(ValueError, match=match):
        ModelSpec(**kw)


def test_spec_round_trips_through_dict():
    spec = ModelSpec(kind="lnn", dof=1, hidden=[16, 16], extra_inputs=1, input_scale=(0.1, 1, 0.1), angle_wrap=True)
    assert spec.hidden == (16, 16)
    assert ModelSpec.from_dict(spec.to_dict()) == spec
    assert hash(spec) == hash(ModelSpec.from_dict(spec.to_dict()))


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("init", INITS)
def test_layout_and_round_trip_through_both_frameworks(kind, init):
    spec = ModelSpec(kind=kind, dof=3, hidden=(8, 8), init=init, dtype="float64")
    params = init_params(spec, seed=3)
    assert {k: v.shape for k, v in params.items()} == param_shapes(spec)
    assert all(v.dtype == np.float64 for v in params.values())
    for mod in (lagbench.models.jax, lagbench.models.torch):
        back = mod.to_params(mod.build(spec, params))
        assert back.keys() == params.keys()
        for k in params:
            np.testing.assert_array_equal(back[k], params[k])
    mt = lagbench.models.torch.build(spec, params)
    assert all(p.requires_grad and p.dtype == torch.float64 for p in mt.parameters())
    np.testing.assert_array_equal(init_params(spec, seed=3)["mlp.0.weight"], params["mlp.0.weight"])


def test_both_registries_come_from_the_capability_table():
    """A kind is one row of `models.spec.CAPABILITIES`: both build registries list exactly its kinds, each
    the class the row names from `models/<framework>/<kind>.py`; the kind-specific checks read the row."""
    from lagbench.models.jax.build import CLASSES as JAX_CLASSES
    from lagbench.models.spec import CAPABILITIES
    from lagbench.models.torch.build import CLASSES as TORCH_CLASSES

    assert KINDS == tuple(CAPABILITIES) == ("baseline", "lnn", "hnn", "delan", "lgn")
    for classes, fw in ((JAX_CLASSES, "jax"), (TORCH_CLASSES, "torch")):
        assert tuple(classes) == KINDS
        for kind, cls in classes.items():
            assert (cls.__module__, cls.__name__) == (f"lagbench.models.{fw}.{kind}", CAPABILITIES[kind].model_class)
    for kind in ("delan", "lgn"):
        with pytest.raises(ValueError, match="takes no extra_inputs"):
            ModelSpec(kind=kind, dof=2, hidden=(8,), extra_inputs=1)
    for kind in ("lnn", "hnn", "lgn"):
        with pytest.raises(ValueError, match="scalar output"):
            ModelSpec(kind=kind, dof=2, hidden=(8,), n_out=2)
    assert ModelSpec(kind="baseline", dof=2, hidden=(8,), n_out=3).mlp_sizes() == (4, 8, 3)
    with pytest.raises(ValueError, match="formulation is for kinds lnn, lgn, not 'delan'"):
        ModelSpec(kind="delan", dof=2, hidden=(8,), formulation="paper")


def test_delan_layout_names():
    spec = ModelSpec(kind="delan", dof=3, hidden=(8, 8))
    assert param_shapes(spec) == {
        "mlp.0.weight": (8, 3), "mlp.0.bias": (8,), "mlp.1.weight": (8, 8), "mlp.1.bias": (8,),
        "delan_lower.weight": (3, 8), "delan_lower.bias": (3,), "delan_diag.weight": (3, 8),
        "delan_diag.bias": (3,), "delan_potential.weight": (1, 8), "delan_potential.bias": (1,)}


def test_cranmer_init_stds_match_the_paper_formula():
    spec = ModelSpec(kind="lnn", dof=2, hidden=(600, 600, 600), init="cranmer2020", dtype="float64")
    params = init_params(spec, seed=0)
    stds = [params[f"mlp.{i}.weight"].std() for i in range(4)]
    np.testing.assert_allclose(stds, [0.0898, 0.0237, 0.0474, 24.49], rtol=0.05)
    assert all(not params[f"mlp.{i}.bias"].any() for i in range(4))


def test_pytorch_default_init_bounds():
    spec = ModelSpec(kind="baseline", dof=2, hidden=(400,), init="pytorch_default")
    params = init_params(spec, seed=0)
    w, b = params["mlp.0.weight"], params["mlp.0.bias"]
    assert np.abs(w).max() <= 0.5 and np.abs(w).max() > 0.49 and np.abs(b).max() <= 0.5
    assert params["mlp.0.weight"].dtype == np.float32


def test_activations_cover_the_paper_study():
    assert set(ACTIVATIONS) == {"softplus", "relu", "relu2", "relu3", "tanh", "sigmoid"}


def test_build_rejects_wrong_params():
    spec = ModelSpec(kind="lnn", dof=2, hidden=(8,))
    params = init_params(spec)
    for mod in (lagbench.models.jax, lagbench.models.torch):
        with pytest.raises(ValueError, match="expected shape"):
            mod.build(spec, params | {"mlp.0.weight": np.zeros((8, 5), np.float32)})
        with pytest.raises(ValueError, match="missing"):
            mod.build(spec, {k: v for k, v in params.items() if k != "mlp.1.bias"})


@pytest.mark.parametrize("fw", ["jax", "torch"])
def test_bad_inputs_give_clear_errors(fw):
    mod, arr = (lagbench.models.jax, jnp.asarray) if fw == "jax" else (lagbench.models.torch, torch.tensor)
    spec = ModelSpec(kind="lnn", dof=2, hidden=(8,), dtype="float64")
    m = mod.build(spec, init_params(spec))
    q = arr(np.zeros((4, 2)))
    with pytest.raises(ValueError, match=r"expected q of shape \(\.\.\., 2\), got shape \(4, 3\)"):
        m.acceleration(arr(np.zeros((4, 3))), arr(np.zeros((4, 3))))
    with pytest.raises(ValueError, match="qdot"):
        m.acceleration(q, arr(np.zeros((5, 2))))
    with pytest.raises(ValueError, match="extra_inputs == 0"):
        m.lagrangian(q, q, arr(np.zeros((4, 1))))
    with pytest.raises(TypeError, match="dtype"):
        m.lagrangian(arr(np.zeros((4, 2), np.float32)), arr(np.zeros((4, 2), np.float32)))
    rel = ModelSpec(kind="lnn", dof=1, hidden=(8,), extra_inputs=1, dtype="float64")
    with pytest.raises(ValueError, match="extra is required"):
        mod.build(rel, init_params(rel)).acceleration(arr(np.zeros((4, 1))), arr(np.zeros((4, 1))))
    delan = ModelSpec(kind="delan", dof=2, hidden=(8,), dtype="float64")
    with pytest.raises(ValueError, match="expected q of shape"):
        mod.build(delan, init_params(delan)).mass_matrix(arr(np.zeros((4, 3))))
