"""Stiff systems: the stiff chain's linearisation, the solver choice and its accuracy (SPEC hard cases)."""

import numpy as np
import pytest

from lagbench import systems
from lagbench.systems.stiffness import linear_rates, pick_solver
from lagbench.systems.trajectories import integrate

ACCURACY = 1e-6   # the rule: final-state error and relative energy drift below this at tol 1e-10


def test_stiff_chain_structure_and_normal_modes():
    s = systems.get("stiff_chain")
    assert s.params["k_stiff"] / s.params["k_soft"] == 1e4
    assert s.structure["quadratic_kinetic"] and s.structure["separable"]
    # at any state (linear system) the eigenvalues are +-i omega of K = [[k + K, -K], [-K, K]] / m
    k, kk = s.params["k_soft"], s.params["k_stiff"]
    omega = np.sqrt(np.linalg.eigvalsh(np.array([[k + kk, -kk], [-kk, kk]])))
    eig = linear_rates(s, np.zeros(2), np.zeros(2))
    np.testing.assert_allclose(np.sort(np.abs(eig.imag)), np.sort(np.repeat(omega, 2)), rtol=1e-10)
    assert np.max(np.abs(eig.real)) < 1e-9


def test_stiff_chain_choice_is_reported_and_accurate():
    s = systems.get("stiff_chain")
    st = s.sample_states(2, 0)
    t_end = 10.0
    choice = pick_solver(s, st["q"], st["qdot"], t_end)
    assert choice.solver == "dopri8" and not choice.dissipative
    assert choice.stiffness_ratio == pytest.approx(200.0, rel=1e-3)
    assert "oscillatory stiffness" in choice.reason and "200" in choice.reason
    t = np.linspace(0.0, t_end, 51)
    q, qd, steps = integrate(s, st["q"], st["qdot"], t, return_steps=True, **choice.kwargs())
    qr, qdr = integrate(s, st["q"], st["qdot"], t, solver="dopri8", rtol=1e-13, atol=1e-13)
    err = np.max(np.abs(np.concatenate([q - qr, qd - qdr], -1)[:, -1]))
    e = s.energy(q, qd)
    drift = np.max(np.abs(e - e[:, :1]) / np.abs(e[:, :1]))
    assert err < ACCURACY and drift < ACCURACY
    assert 0.3 * choice.expected_steps < np.mean(steps) < 3 * choice.expected_steps


def test_dissipative_stiffness_picks_the_implicit_solver():
    s = systems.get("pendulum", friction=1e3)   # eigenvalues about -1e3 and -g / friction = -3e-3
    q0, qd0 = np.array([[0.5]]), np.array([[0.0]])
    choice = pick_solver(s, q0, qd0, 5.0, tol=1e-8)
    assert choice.solver == "kvaerno5" and choice.dissipative and choice.stiffness_ratio > 1e5
    assert "dissipative" in choice.reason
    # (integrating it is left out: compiling kvaerno5 alone takes ~20 s on 2 cores)


def test_non_stiff_system_keeps_dopri8():
    s = systems.get("double_pendulum")
    choice = pick_solver(s, np.array([0.3, 0.2]), np.array([0.0, 0.0]), 10.0)
    assert choice.solver == "dopri8" and choice.stiffness_ratio < 100 and choice.reason.startswith("not stiff")


@pytest.mark.parametrize("kwargs,match", [({"t_end": -1.0}, "t_end"), ({"t_end": 1.0, "tol": 0.0}, "tol")])
def test_bad_arguments_raise(kwargs, match):
    s = systems.get("stiff_chain")
    with pytest.raises(ValueError, match=match):
        pick_solver(s, np.zeros(2), np.zeros(2), **kwargs)
    with pytest.raises(ValueError, match="shape"):
        linear_rates(s, np.zeros(3), np.zeros(3))
