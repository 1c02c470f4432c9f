from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
ROBOTS = ROOT / "robots"
DATA = Path(__file__).resolve().parent / "data"
CORPUS = ROOT.parent / "shared" / "corpus" / "example-parallel-robots"


@pytest.fixture
def quiet():
    """A warn callable that collects warnings instead of printing them."""
    seen = []
    return seen.append


LINK = ('<link name="{n}"><inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/>'
        '</inertial><visual><geometry><box size="0.01 0.01 0.01"/></geometry></visual></link>')
DUMMY = '<link name="{n}"/>'


def rev(name, parent, child, axis="0 0 1", xyz="0 0 0", rpy="0 0 0", jtype="revolute"):
    return (f'<joint name="{name}" type="{jtype}"><parent link="{parent}"/><child link="{child}"/>'
            f'<origin xyz="{xyz}" rpy="{rpy}"/><axis xyz="{axis}"/>'
            f'<limit lower="-3" upper="3" effort="1" velocity="1"/></joint>')


def fourbar(loop_children='<link1 link="coupler" xyz="0.12 0 0"/><link2 link="rocker" xyz="0.08 0 0"/>',
            extra=""):
    # ground pivots A=(0,0), D=(0.1,0); crank 0.04 at 90 deg; coupler 0.12 and rocker 0.08
    # placed with the angles of the closed loop (computed from the two circle intersection).
    B = np.array([0.0, 0.04])
    D = np.array([0.1, 0.0])
    d = np.linalg.norm(D - B)
    a = (0.12**2 - 0.08**2 + d**2) / (2 * d)
    h = np.sqrt(0.12**2 - a**2)
    u = (D - B) / d
    C = B + a * u + h * np.array([-u[1], u[0]])
    th_c = np.arctan2(*(C - B)[::-1])
    th_r = np.arctan2(*(C - D)[::-1])
    body = "".join(LINK.format(n=n) for n in ("ground", "crank", "coupler", "rocker"))
    body += rev("crank_joint", "ground", "crank", rpy="0 0 1.5707963267948966")
    body += rev("coupler_joint", "crank", "coupler", xyz="0.04 0 0", rpy=f"0 0 {th_c - np.pi / 2}")
    body += rev("rocker_joint", "ground", "rocker", xyz="0.1 0 0", rpy=f"0 0 {th_r}")
    body += f'<loop_joint name="C" type="revolute">{loop_children}<axis xyz="0 0 1"/></loop_joint>'
    return f'<robot name="fourbar">{body}{extra}</robot>'


