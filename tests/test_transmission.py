"""analysis.motion.planar.transmission_angles: one identification, a stack of configurations, against
the law of cosines (four-bar) and the slider-crank's closed form, written here."""

import numpy as np
import screwkin
from conftest import ROBOTS
from screwkin.analysis.motion.planar import identify, transmission_angles
from screwkin.analysis.motion.position import PositionSolver

DRAWN = np.radians(60)  # both files are drawn with the crank at 60 deg from the world x axis
CRANKS = np.radians([0.0, 30.0, 75.0, 140.0, 200.0, 260.0, 330.0])  # crank_joint values


def _stack(mech):
    solver = PositionSolver(mech, ["crank_joint"])
    q = mech.assemble().q
    Q = []
    for x in CRANKS:
        q = solver.track({"crank_joint": float(x)}, q).q
        Q.append(q)
    info = identify(mech, mech.topology(Q[0]), Q[0], "crank_joint")
    return info, np.array(Q)


def test_four_bar_law_of_cosines():
    """Ground g = 0.10 along +x, crank a = 0.04, coupler b = 0.12, rocker c = 0.08: at crank
    angle t the diagonal z^2 = a^2 + g^2 - 2 a g cos t, and cos mu = (b^2 + c^2 - z^2) / (2 b c)."""
    mech = screwkin.load(ROBOTS / "fourbar_crank_rocker.urdf")
    g, a, b, c = 0.10, 0.04, 0.12, 0.08
    info, Q = _stack(mech)
    assert info.kind == "four-bar"
    mus = transmission_angles(mech, info, Q)
    assert mus.shape == (len(CRANKS),)
    t = DRAWN + CRANKS
    z2 = a * a + g * g - 2 * a * g * np.cos(t)
    np.testing.assert_allclose(mus, np.arccos((b * b + c * c - z2) / (2 * b * c)), rtol=0, atol=1e-8)
    # the identification's own angle at its configuration is the same number
    assert abs(info.transmission_angle - mus[0]) < 1e-12


def test_slider_crank_closed_form():
    """Crank a = 0.05 about the origin, rod b = 0.15, slide along x at y = e = 0.02: the rod's
    angle with the slide's normal is arccos(|e - a sin t| / b)."""
    mech = screwkin.load(ROBOTS / "slider_crank_offset.urdf")
    a, b, e = 0.05, 0.15, 0.02
    info, Q = _stack(mech)
    assert info.kind == "slider-crank"
    mus = transmission_angles(mech, info, Q)
    t = DRAWN + CRANKS
    np.testing.assert_allclose(mus, np.arccos(np.abs(e - a * np.sin(t)) / b), rtol=0, atol=1e-8)


def test_one_configuration_and_not_a_linkage():
    mech = screwkin.load(ROBOTS / "fourbar_crank_rocker.urdf")
    info, Q = _stack(mech)
    assert transmission_angles(mech, info, Q[2]).shape == (1,)  # one configuration: a stack of one
    five = screwkin.load(ROBOTS / "five_bar.urdf")
    q = five.assemble().q
    assert identify(five, five.topology(q), q, five.actuated[0]) is None


def test_compound_joint_centres_from_the_topology():
    """A joint made of several tree joints has no one frame: its centre comes from the topology
    rebuilt at each configuration; with every centre found that way the angles are the same."""
    from dataclasses import replace

    mech = screwkin.load(ROBOTS / "fourbar_crank_rocker.urdf")
    info, Q = _stack(mech)
    slow = replace(info, centres=tuple(("topology", n) for n in
                                       ("crank_joint", "coupler_joint", "coupler_rocker", "rocker_joint")))
    np.testing.assert_allclose(transmission_angles(mech, slow, Q), transmission_angles(mech, info, Q),
                               rtol=0, atol=1e-12)
