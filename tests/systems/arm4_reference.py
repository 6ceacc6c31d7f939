"""An independent NumPy model of ``four_joint_arm`` for its tests (no SymPy, no generated code).

Written from the geometry alone: the bodies' frames from elementary rotations, the joint axes and
origins in world axes, the geometric Jacobians (linear part z_i x (p - o_i), angular part z_i), so

- ``mass_matrix(q, p)`` = I0 e1 e1^T + sum_bodies m J_v^T J_v + J_w^T R I_b R^T J_w  (4, 4);
- ``gravity(q, p)`` = g sum_bodies m dz_com/dq  (4,);
- ``inverse_dynamics(q, qdot, qddot, p)`` = M qddot + dM/dt qdot - 1/2 d(qdot^T M qdot)/dq + g(q)
  + friction qdot + coulomb tanh(qdot / coulomb_speed), the time and q derivatives of M by central
  differences (step ``h``).

``p`` is a dict of the system's parameters (``System.params``); q, qdot, qddot are one state, (4,).
"""

from __future__ import annotations

import numpy as np

E_X, E_Y, E_Z = np.eye(3)


def rot(axis: str, a: float) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    if axis == "x":
        return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])
    if axis == "y":
        return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def frames(q, p) -> dict:
    r_base = rot("z", q[0])
    r_pitch = r_base @ rot("y", -q[1])
    r_upper = r_pitch @ rot("x", q[2])
    r_fore = r_upper @ rot("y", -q[3])
    elbow = p["l1"] * r_upper @ E_X
    return {
        "r_upper": r_upper, "r_fore": r_fore,
        "com_upper": p["lc1"] * r_upper @ E_X, "com_fore": elbow + p["lc2"] * r_fore @ E_X,
        # joint axes (the direction of each joint's angular velocity) and points on them
        "axes": [E_Z, r_base @ -E_Y, r_upper @ E_X, r_upper @ -E_Y],
        "origins": [np.zeros(3)] * 3 + [elbow],
    }


def _jacobians(f: dict, com: np.ndarray, n_joints: int) -> tuple[np.ndarray, np.ndarray]:
    jv, jw = np.zeros((3, 4)), np.zeros((3, 4))
    for i in range(n_joints):
        jw[:, i] = f["axes"][i]
        jv[:, i] = np.cross(f["axes"][i], com - f["origins"][i])
    return jv, jw


def mass_matrix(q, p) -> np.ndarray:
    f = frames(q, p)
    m = np.zeros((4, 4))
    m[0, 0] = p["I0"]
    bodies = [("upper", 1, 3), ("fore", 2, 4)]
    for name, i, n_joints in bodies:
        jv, jw = _jacobians(f, f[f"com_{name}"], n_joints)
        r = f[f"r_{name}"]
        inertia = r @ np.diag([p[f"Ia{i}"], p[f"It{i}"], p[f"It{i}"]]) @ r.T
        m += p[f"m{i}"] * jv.T @ jv + jw.T @ inertia @ jw
    return m


def gravity(q, p) -> np.ndarray:
    f = frames(q, p)
    jv_u, _ = _jacobians(f, f["com_upper"], 3)
    jv_f, _ = _jacobians(f, f["com_fore"], 4)
    return p["g"] * (p["m1"] * jv_u[2] + p["m2"] * jv_f[2])


def inverse_dynamics(q, qdot, qddot, p, h: float = 1e-5) -> np.ndarray:
    q, qdot, qddot = (np.asarray(x, dtype=float) for x in (q, qdot, qddot))
    m_dot = (mass_matrix(q + h * qdot, p) - mass_matrix(q - h * qdot, p)) / (2 * h)
    grad = np.zeros(4)
    for k in range(4):
        dq = h * np.eye(4)[k]
        grad[k] = qdot @ (mass_matrix(q + dq, p) - mass_matrix(q - dq, p)) @ qdot / (2 * h)
    friction = p["friction"] * qdot + p["coulomb"] * np.tanh(qdot / p["coulomb_speed"])
    return mass_matrix(q, p) @ qddot + m_dot @ qdot - grad / 2 + gravity(q, p) + friction
