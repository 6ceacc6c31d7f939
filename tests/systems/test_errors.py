"""Bad input gives clear errors: names, shapes, parameters, backends, speeds; plus a property test."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from lagbench import systems


def test_names_are_the_spec_table():
    assert systems.names() == sorted(["free_fall", "pendulum", "spring", "double_pendulum", "relativistic",
                                      "relativistic_standard", "charged_magnetic", "wave", "two_link_arm",
                                      "four_joint_arm", "pendulum_chain", "stiff_chain"])


def test_unknown_name_lists_valid_names():
    with pytest.raises(KeyError, match="double_pendulum.*two_link_arm"):
        systems.get("dubble_pendulum")


@pytest.mark.parametrize("name,kwargs,match", [
    ("double_pendulum", {"m1": -1.0}, "m1.*> 0"),
    ("double_pendulum", {"l2": 0.0}, "l2.*> 0"),
    ("two_link_arm", {"friction": -0.1}, "friction.*>= 0"),
    ("two_link_arm", {"lc2": 0.5}, "lc2.*must not exceed l2"),
    ("pendulum", {"mass": 1.0}, "valid parameters: friction, g, l, m"),
    ("wave", {"n": 2}, "n >= 3"),
    ("wave", {"variant": "exact"}, "code, textbook"),
    ("pendulum_chain", {"n": 0}, "n >= 1"),
    ("spring", {"k": float("nan")}, "finite"),
])
def test_non_physical_parameters_raise(name, kwargs, match):
    with pytest.raises(ValueError, match=match):
        systems.get(name, **kwargs)


def test_per_call_overrides_are_validated():
    s = systems.get("double_pendulum")
    with pytest.raises(ValueError, match="m2"):
        s.acceleration(np.zeros(2), np.zeros(2), m2=np.array([1.0, -1.0]))


def test_wrong_trailing_dimension_names_expected_shape():
    s = systems.get("double_pendulum")
    with pytest.raises(ValueError, match=r"shape \(\.\.\., 2\); got \(5, 3\)"):
        s.acceleration(np.zeros((5, 3)), np.zeros((5, 2)))
    with pytest.raises(ValueError, match="do not broadcast"):
        s.acceleration(np.zeros((5, 2)), np.zeros((4, 2)))
    with pytest.raises(ValueError, match="backend"):
        s.energy(np.zeros(2), np.zeros(2), backend="tensorflow")


@pytest.mark.parametrize("name", ["relativistic", "relativistic_standard"])
@pytest.mark.parametrize("speed", [1.0, -1.0, 1.5])
def test_speed_of_light(name, speed):
    s = systems.get(name)
    with pytest.raises(ValueError, match="< 1"):
        s.acceleration(np.zeros((3, 1)), np.array([[0.1], [speed], [0.2]]))
    with pytest.raises(ValueError, match="< 1"):
        s.energy(np.zeros(1), np.array([speed]))


def test_mass_matrix_refused_where_kinetic_term_is_not_quadratic():
    s = systems.get("charged_magnetic")
    assert not s.structure["quadratic_kinetic"]
    with pytest.raises(systems.NotQuadraticError, match="not quadratic"):
        s.mass_matrix(np.zeros(2))
    np.testing.assert_array_equal(s.velocity_hessian(np.zeros(2), np.ones(2)), np.eye(2))


_FAST = ["free_fall", "pendulum", "spring", "double_pendulum", "charged_magnetic", "relativistic"]


@settings(max_examples=40, deadline=None)
@given(name=st.sampled_from(_FAST), batch=st.lists(st.integers(0, 3), max_size=3),
       extra_dim=st.sampled_from([0, 0, 0, 1, -1]), seed=st.integers(0, 2**16),
       method=st.sampled_from(["acceleration", "energy", "canonical_momentum"]))
def test_public_api_gives_a_clean_error_or_a_correct_result(name, batch, extra_dim, seed, method):
    s = systems.get(name)
    dof = s.dof + extra_dim
    rng = np.random.default_rng(seed)
    q = rng.uniform(-3, 3, (*batch, max(dof, 0)))
    qdot = rng.uniform(-0.9, 0.9, q.shape)
    fn = getattr(s, method)
    if extra_dim != 0:
        with pytest.raises(ValueError, match=f"shape \\(\\.\\.\\., {s.dof}\\)"):
            fn(q, qdot)
        return
    out = fn(q, qdot)
    expected = tuple(batch) if method == "energy" else (*batch, s.dof)
    assert out.shape == expected and out.dtype == np.float64
    assert np.all(np.isfinite(out))
    if out.size:  # the batched result equals the row-by-row one
        idx = tuple(0 for _ in batch)
        np.testing.assert_allclose(out[idx], fn(q[idx], qdot[idx]), rtol=1e-14, atol=1e-14)
