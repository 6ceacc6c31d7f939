"""LNN Appendix B: the Euler-Lagrange equations of 2D free fall give exactly qddot = (-g, 0)."""

import numpy as np
import sympy as sp

from lagbench import systems


def test_free_fall_symbolic_answer_is_minus_g_zero():
    s = systems.get("free_fall")
    dv = systems.system._derivation(s.definition)
    g, m = s.param_symbols["g"], s.param_symbols["m"]
    free = [e.xreplace({t: 0 for t in dv.tau_syms}) for e in dv.acceleration]
    assert free == [-g, sp.Integer(0)]
    assert dv.hessian == sp.Matrix([[m, 0], [0, m]]) and dv.mixed == sp.zeros(2, 2)


def test_free_fall_numeric_answer_is_exact():
    s = systems.get("free_fall", g=9.81, m=2.5)
    st = s.sample_states(100, 0)
    acc = s.acceleration(st["q"], st["qdot"])
    assert np.array_equal(acc, np.broadcast_to([-9.81, 0.0], acc.shape))
    h = s.velocity_hessian(st["q"], st["qdot"])
    assert np.array_equal(h, np.broadcast_to(2.5 * np.eye(2), h.shape))
