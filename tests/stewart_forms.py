"""Gough-Stewart platforms written two ways from one geometry, for the tests that compare them.

``urdf(base, plat, R, t, form)``: base points A_k (world), platform points B_k (platform frame), the
platform drawn at the pose (R, t) (P_k = R B_k + t in the world), U-P-S legs (a universal joint of
two revolutes at A_k, an actuated prismatic joint ``leg{k}`` along the drawn leg, a spherical joint
at P_k).  ``form="tree"``: as robots/gough_stewart_6ups.urdf is written -- leg 1 carries the platform
through three revolutes (its spherical joint), legs 2..6 close with spherical loop joints;
``form="floating"``: the platform on a floating joint, all six legs closed by spherical loop joints.
Leg values 0 are the drawn lengths |P_k - A_k|.  ``pose_of(mech, q)`` is the platform's pose (R, t)
in the geometry's own platform frame.

Dietmaier's platform (40 real assembly modes): tests/data/stewgou40.json (its source and licence
there)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pinocchio as pin

DATA = Path(__file__).parent / "data"


def _v(a):
    return " ".join(f"{x:.17g}" for x in a)


_INERTIAL = ('<inertial><mass value="0.3"/><inertia ixx="1e-3" iyy="1e-3" izz="1e-3" ixy="0" ixz="0" '
             'iyz="0"/></inertial>')


def urdf(base, plat, R, t, form: str = "tree", name: str = "stewart") -> str:
    base, plat = np.asarray(base, float), np.asarray(plat, float)
    P = plat @ np.asarray(R, float).T + np.asarray(t, float)  # drawn platform points, world
    out = ['<?xml version="1.0"?>', f'<robot name="{name}">', f'<link name="base">{_INERTIAL}</link>',
           f'<link name="platform">{_INERTIAL}</link>']
    if form == "floating":  # platform frame at P_1, axes of the world (as the tree form's)
        out.append(f'<joint name="free" type="floating"><parent link="base"/><child link="platform"/>'
                   f'<origin xyz="{_v(P[0])}"/></joint>')
    for k in range(6):
        d = P[k] - base[k]
        d /= np.linalg.norm(d)
        a1 = np.cross(d, [0.3, 0.2, 1.0])
        a1 /= np.linalg.norm(a1)
        a2 = np.cross(d, a1)
        n = k + 1
        out += [f'<link name="u{n}"/>', f'<link name="cyl{n}">{_INERTIAL}</link>',
                f'<link name="pis{n}">{_INERTIAL}</link>',
                f'<joint name="u{n}a" type="revolute"><parent link="base"/><child link="u{n}"/>'
                f'<origin xyz="{_v(base[k])}"/><axis xyz="{_v(a1)}"/>'
                '<limit lower="-3" upper="3" effort="1" velocity="1"/></joint>',
                f'<joint name="u{n}b" type="revolute"><parent link="u{n}"/><child link="cyl{n}"/>'
                f'<origin xyz="0 0 0"/><axis xyz="{_v(a2)}"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>',
                f'<joint name="leg{n}" type="prismatic"><parent link="cyl{n}"/><child link="pis{n}"/>'
                f'<origin xyz="0 0 0"/><axis xyz="{_v(d)}"/><limit lower="-5" upper="5" effort="1" velocity="1"/></joint>',
                f'<transmission name="t{n}"><joint name="leg{n}"/></transmission>']
        if k == 0 and form == "tree":
            out += ['<link name="b1"/>', '<link name="b2"/>']
            for jn, axis, p, c in (("s1x", "1 0 0", "pis1", "b1"), ("s1y", "0 1 0", "b1", "b2"),
                                   ("s1z", "0 0 1", "b2", "platform")):
                xyz = _v(P[0] - base[0]) if p == "pis1" else "0 0 0"
                out.append(f'<joint name="{jn}" type="revolute"><parent link="{p}"/>'
                           f'<child link="{c}"/><origin xyz="{xyz}"/><axis xyz="{axis}"/><limit lower="-3.1" upper="3.1" effort="1" velocity="1"/></joint>')
        else:
            out.append(f'<loop_joint name="s{n}" type="spherical"><link1 link="pis{n}" xyz="{_v(P[k] - base[k])}"/>'
                       f'<link2 link="platform" xyz="{_v(P[k] - P[0])}"/></loop_joint>')
    out.append("</robot>")
    return "\n".join(out)


def pose_of(mech, q, R_drawn, plat):
    """The platform's pose (R, t) as the geometry's: P_k = R B_k + t for every k."""
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, np.asarray(q, float))
    M = data.oMf[mech.model.getFrameId("platform")]
    # the frame holds P_k - P_1 = R_drawn (B_k - B_1): world = M.R R_drawn (B - B_1) + M.t
    Rg = M.rotation @ np.asarray(R_drawn)
    return Rg, M.translation - Rg @ plat[0]


def leg_lengths(base, plat, R, t):
    return np.linalg.norm(plat @ np.asarray(R).T + t - base, axis=1)


def dietmaier():
    """Dietmaier's geometry and PHCpack's 40 real poses (R, t) (tests/data/stewgou40.json)."""
    d = json.loads((DATA / "stewgou40.json").read_text())
    base, plat, lengths = np.array(d["base"]), np.array(d["platform"]), np.array(d["lengths"])
    poses = []
    for s in d["solutions"]:
        n, a1, a2 = np.array(s["n"]), np.array(s["a1"]), np.array(s["a2"])
        poses.append((np.c_[a1, a2, np.cross(a1, a2)], n))  # B_1 = 0 sits at A_1 + n = n
    return base, plat, lengths, poses


def random_geometry(seed: int, planar: bool = False):
    """Base and platform points of a random 6-6 platform and a drawn pose (R, t)."""
    rng = np.random.default_rng(seed)
    base = rng.uniform(-0.5, 0.5, (6, 3)) * [1, 1, 0 if planar else 0.2]
    plat = rng.uniform(-0.3, 0.3, (6, 3)) * [1, 1, 0 if planar else 0.3]
    R = pin.rpy.rpyToMatrix(*rng.uniform(-0.2, 0.2, 3))
    t = np.array([0.02, -0.03, 0.7])
    return base, plat, R, t
