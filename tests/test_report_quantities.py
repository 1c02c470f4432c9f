"""report's positions, velocities and accelerations in the user's quantities (issue 24 items 1, 2, 8):
the offset slider-crank robots/slider_crank_offset.urdf against its closed form written here.

Geometry from the URDF (its comment and joints): the crank (r = 0.05 m) turns about the ground's
origin and is drawn at 60 deg at crank_joint = 0, so its absolute angle is t = 60 deg + crank_joint;
the rod (l = 0.15 m) runs from the crank tip to the slider's pin, which slides on the line y = e =
0.02 m (slider_joint's origin x0 = 0.1731791173126931 m, axis +x).  With the pin at (x, e):
    (x - r cos t)^2 + (e - r sin t)^2 = l^2  ->  x = r cos t + sqrt(l^2 - (r sin t - e)^2)
(the + root: the drawn mode, pin to the right of the crank tip); slider_joint = x - x0.  Rates by
differentiating in t (t' = w, t'' = 0), the rod's absolute angle phi = atan2(e - r sin t, x - r cos t)."""

import json
import math

import numpy as np
import pytest
from conftest import ROBOTS

import screwkin
from screwkin.analysis.motion.planar import LinkAngles
from screwkin.analysis.motion.position import PositionSolver

SLIDER_CRANK = str(ROBOTS / "slider_crank_offset.urdf")
R, L, E, X0 = 0.05, 0.15, 0.02, 0.1731791173126931
DRAWN = math.radians(60.0)


def closed_form(t, w):
    """Slider x, x', x'' and the rod's phi, omega, alpha at absolute crank angle t, rate w (alpha_crank 0)."""
    s = R * math.sin(t) - E
    root = math.sqrt(L**2 - s**2)
    x = R * math.cos(t) + root
    ds = R * math.cos(t) * w  # s'
    dds = -R * math.sin(t) * w**2  # s''
    xd = -R * math.sin(t) * w - s * ds / root
    xdd = -R * math.cos(t) * w**2 - (ds**2 + s * dds) / root - (s * ds) ** 2 / root**3
    phi = math.atan2(-s, root)  # from the crank tip to the pin: (root, -s)
    # sin phi = -s / l  ->  omega cos phi = -s'/l ; alpha cos phi - omega^2 sin phi = -s''/l
    omega = -ds / (L * math.cos(phi))
    alpha = (-dds / L + omega**2 * math.sin(phi)) / math.cos(phi)
    return x, xd, xdd, phi, omega, alpha


def test_link_angles_do_not_move_with_a_prismatic_child():
    """The ground's vector-loop line runs from the crank pivot to where slider_joint is mounted: a constant
    angle atan2(e, x0), whatever the slider's position (it followed the slider before: 7.75 deg at 30 deg)."""
    mech = screwkin.load(SLIDER_CRANK)
    solver = PositionSolver(mech, ["crank_joint"])
    qs = [solver.solve({"crank_joint": math.radians(a)}).solutions[0].q for a in (30, 100, 250)]
    angles = LinkAngles(mech, mech.topology(qs[0]))
    for q in qs:
        assert angles(q)["ground"] == pytest.approx(math.atan2(E, X0), abs=1e-12)
    batch = angles.batch(np.array(qs))
    np.testing.assert_allclose(batch["ground"], math.atan2(E, X0), rtol=0, atol=1e-12)
    for q, rod in zip(qs, batch["rod"]):
        assert rod == pytest.approx(angles(q)["rod"], abs=1e-12)
