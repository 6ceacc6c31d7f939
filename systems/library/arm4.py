"""A spatial four-joint arm with joint torques: the first four joints of a Barrett WAM (DeLaN).

Joints (rad), world axes x, y horizontal and z up, the shoulder at the origin:

- q1 base yaw about the vertical z axis;
- q2 shoulder pitch: the elevation of the upper arm above the horizontal (positive raises it);
- q3 upper-arm roll: the twist of the upper arm about its own long axis;
- q4 elbow pitch: the angle of the forearm relative to the upper arm, in the same sense as q2.

Orientations (body axes to world axes, each body's long axis its own x axis):
R_base = Rz(q1), R_upper = R_base Ry(-q2) Rx(q3), R_fore = R_upper Ry(-q4). At q = 0 the arm points
straight out along x. The elbow lies on the upper arm's axis at l1 from the shoulder (no elbow offset),
so with q3 = 0 the pitch joints q2, q4 move the arm in a vertical plane exactly as ``two_link_arm``'s
q1, q2 (same parameter names: m, l, lc; ``two_link_arm``'s I is the transverse It here).

Bodies: the turning shoulder housing, of inertia I0 about the vertical axis (its centre of mass on the
axis: it adds no potential energy that changes); the upper arm and the forearm, uniform solid cylinders
along their x axes: mass m_i, length l_i, centre of mass at lc_i along the axis, inertia tensor about the
centre of mass diag(Ia_i, It_i, It_i) in the body's axes (Ia axial, It transverse). Gravity g along -z.
The Lagrangian is derived from the centres of mass (3D) and the bodies' angular velocities
(``systems.spatial``: w from R^T dR/dt, in body axes):
L = sum_i [m_i/2 |v_i|^2 + 1/2 w_i^T I_i w_i] + I0/2 q1dot^2 - g sum_i m_i z_i.

Defaults (WAM-like; SI units): I0 = 0.1125 kg m^2 (a 10 kg cylinder of radius 0.15 m); upper arm
m1 = 5.7 kg, l1 = 0.55 m, lc1 = 0.275 m, a cylinder of radius 0.06 m (Ia1 = m r^2/2 = 0.01026,
It1 = m (3 r^2 + l^2)/12 = 0.14882 kg m^2); forearm m2 = 2.9 kg, l2 = 0.35 m, lc2 = 0.175 m, radius
0.04 m (Ia2 = 0.00232, It2 = 0.030764 kg m^2); g = 9.81 m/s^2.

Joint friction, generalised force on each joint i: -friction * qdot_i (viscous, N m s/rad) minus
coulomb * tanh(qdot_i / coulomb_speed) (Coulomb, N m, smoothed over coulomb_speed = 0.05 rad/s so the
equations of motion stay smooth for the integrators); friction = coulomb = 0 by default. The torques tau
are the joints' generalised forces: M(q) qddot + c(q, qdot) + g(q) = tau + friction forces.

Sampler ("default"): q ~ U[-pi, pi)^4, qdot ~ U[-2, 2)^4 rad/s.
"""

from __future__ import annotations

import numpy as np
import sympy as sp

from lagbench.systems.definition import Definition, coordinates, param
from lagbench.systems.library._sampling import unknown
from lagbench.systems.spatial import body_angular_velocity, body_velocity, rotation

COULOMB_SPEED = 0.05  # rad/s, the default smoothing speed of the Coulomb friction


def cylinder_inertia(m: float, length: float, radius: float) -> tuple[float, float]:
    """(axial, transverse) moments of inertia of a uniform solid cylinder about its centre of mass."""
    return m * radius**2 / 2, m * (3 * radius**2 + length**2) / 12


_IA1, _IT1 = cylinder_inertia(5.7, 0.55, 0.06)
_IA2, _IT2 = cylinder_inertia(2.9, 0.35, 0.04)


def _params() -> dict:
    return {
        "I0": param("I0", 10.0 * 0.15**2 / 2),
        "m1": param("m1", 5.7), "l1": param("l1", 0.55), "lc1": param("lc1", 0.275),
        "Ia1": param("Ia1", _IA1), "It1": param("It1", _IT1),
        "m2": param("m2", 2.9), "l2": param("l2", 0.35), "lc2": param("lc2", 0.175),
        "Ia2": param("Ia2", _IA2), "It2": param("It2", _IT2),
        "g": param("g", 9.81, "nonnegative"),
        "friction": param("friction", 0.0, "nonnegative"),
        "coulomb": param("coulomb", 0.0, "nonnegative"),
        "coulomb_speed": param("coulomb_speed", COULOMB_SPEED),
    }


def _rigid_body_energy(m, inertia, rot, com, q, v) -> sp.Expr:
    """m/2 |v_com|^2 + 1/2 w^T diag(Ia, It, It) w, both in the body's own axes."""
    ia, it = inertia
    vel = body_velocity(rot, com, q, v)
    w = body_angular_velocity(rot, q, v)
    return m / 2 * sum(e**2 for e in vel) + (ia * w[0] ** 2 + it * (w[1] ** 2 + w[2] ** 2)) / 2


def build_four_joint_arm() -> Definition:
    q, v = coordinates(["q1", "q2", "q3", "q4"])
    p = _params()
    s = {k: sym for k, (sym, _, _) in p.items()}
    axis = sp.Matrix([1, 0, 0])
    r_base = rotation("z", q[0])
    r_upper = r_base * rotation("y", -q[1]) * rotation("x", q[2])
    r_fore = r_upper * rotation("y", -q[3])
    com_upper = r_upper * axis * s["lc1"]
    com_fore = r_upper * axis * s["l1"] + r_fore * axis * s["lc2"]
    kinetic = (s["I0"] * v[0] ** 2 / 2
               + _rigid_body_energy(s["m1"], (s["Ia1"], s["It1"]), r_upper, com_upper, q, v)
               + _rigid_body_energy(s["m2"], (s["Ia2"], s["It2"]), r_fore, com_fore, q, v))
    potential = s["g"] * (s["m1"] * com_upper[2] + s["m2"] * com_fore[2])
    forces = tuple(-s["friction"] * vi - s["coulomb"] * sp.tanh(vi / s["coulomb_speed"]) for vi in v)

    def sampler(n, rng, params, distribution):
        if distribution != "default":
            raise unknown(distribution, ["default"])
        return {"q": rng.uniform(-np.pi, np.pi, (n, 4)), "qdot": rng.uniform(-2.0, 2.0, (n, 4))}

    def validate(values):
        for i in (1, 2):
            if values[f"lc{i}"] > values[f"l{i}"]:
                raise ValueError(f"four_joint_arm: lc{i} (centre of mass) must not exceed l{i} (link length)")
            if values[f"Ia{i}"] > 2 * values[f"It{i}"]:
                raise ValueError(f"four_joint_arm: Ia{i} must not exceed 2 It{i} (no rigid body has such "
                                 "principal moments)")

    return Definition("four_joint_arm", q, v, kinetic - potential, p, sampler, forces=forces, actuated=True,
                      validate=validate,
                      description="spatial 4-joint arm (WAM's first four: yaw, pitch, roll, elbow) with joint torques")
