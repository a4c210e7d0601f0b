"""The four-bar linkage of sympy.physics.mechanics' test_jointsmethod
(test_four_bar_linkage_with_manual_constraints) with System: four uniform links of density
rho, three PinJoints with relative angles q1..q3 and speeds u1..u3 (kdes u - q' = 0), the
loop closed by two configuration constraints, gravity along -N.y, a torsion spring k on
joint 1 (a TorqueActuator)."""
from __future__ import annotations

import sympy as sp
from sympy.physics.mechanics import (Lagrangian, PinJoint, RigidBody, System, TorqueActuator, dynamicsymbols,
                                     inertia)

from derive.model import Model, Parameter

PARAMETERS = [Parameter("l1", "m", 0.13, "link 1 (ground)"), Parameter("l2", "m", 0.24, "link 2"),
              Parameter("l3", "m", 0.21, "link 3"), Parameter("l4", "m", 0.34, "link 4"),
              Parameter("rho", "kg/m", 2.0, "linear density"), Parameter("k", "N m/rad", 0.5, "spring at joint 1"),
              Parameter("g", "m/s^2", 9.81, "gravity")]
INDEPENDENT = ["q1"]


def system():
    q1, q2, q3, u1, u2, u3 = dynamicsymbols("q1:4, u1:4")
    l1, l2, l3, l4, rho, k, g = sp.symbols("l1:5 rho k g", positive=True)
    links = [RigidBody(f"Link{i + 1}", mass=rho * l) for i, l in enumerate((l1, l2, l3, l4))]
    for b, l in zip(links, (l1, l2, l3, l4)):
        b.inertia = (inertia(b.frame, 0, 0, rho * l**3 / 12), b.masscenter)
    link1, link2, link3, link4 = links
    j1 = PinJoint("J1", link1, link2, coordinates=q1, speeds=u1, joint_axis=link1.z,
                  parent_point=l1 / 2 * link1.x, child_point=-l2 / 2 * link2.x)
    j2 = PinJoint("J2", link2, link3, coordinates=q2, speeds=u2, joint_axis=link2.z,
                  parent_point=l2 / 2 * link2.x, child_point=-l3 / 2 * link3.x)
    j3 = PinJoint("J3", link3, link4, coordinates=q3, speeds=u3, joint_axis=link3.z,
                  parent_point=l3 / 2 * link3.x, child_point=-l4 / 2 * link4.x)
    s = System.from_newtonian(link1)
    s.add_joints(j1, j2, j3)
    loop = link4.masscenter.pos_from(link1.masscenter) + l1 / 2 * link1.x + l4 / 2 * link4.x
    s.q_ind, s.q_dep = [q1], [q2, q3]
    s.u_ind, s.u_dep = [u1], [u2, u3]
    s.add_holonomic_constraints(loop.dot(link1.x), loop.dot(link1.y))
    s.add_actuators(TorqueActuator(-k * q1, link1.z, link2, link1))
    s.apply_uniform_gravity(-g * link1.y)
    return s, Lagrangian(link1.frame, link2, link3, link4)


def reference():
    s, _ = system()
    s.validate_system()
    s.form_eoms()
    return "kane", s.eom_method


def build() -> Model:
    s, L = system()
    loads = list(s.loads) + [ld for a in s.actuators for ld in a.to_loads()]
    return Model(name="four_bar_joints", title="Four-bar linkage from joints", source="sympy test_jointsmethod",
                 module=__name__, parameters=PARAMETERS, coordinates=["q1", "q2", "q3"],
                 coordinate_units={c: "rad" for c in ("q1", "q2", "q3")}, q=list(s.q), qd=list(s.u), qdd=[],
                 lagrangian=L, loads=loads, frame=s.frame, kinematics=list(s.kdes),
                 holonomic=list(s.holonomic_constraints), reduced=INDEPENDENT)
