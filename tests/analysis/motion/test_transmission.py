"""analysis.motion.planar.transmission_angles: one identification, a stack of configurations, against
the law of cosines (four-bar) and the slider-crank's closed form, written here."""

import numpy as np
import pytest
import screwkin
from conftest import ROBOTS
from screwkin.analysis.motion.planar import identify, transmission_angles
from screwkin.analysis.position.position import PositionSolver

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


# ------------------------------------------------------------------ the range over the whole motion, located
from screwkin.analysis.motion.sweep import sweep  # noqa: E402
from screwkin.analysis.motion.transmission import (  # noqa: E402
    FOUR_BAR_CLASSES,
    four_bar_classes,
    four_bar_transmission,
    slider_crank_transmission,
)

FAMILY = ROBOTS / "fourbar.urdf.xacro"
# (crank, coupler, rocker) with ground 0.1: crank-rocker, double crank, double rocker, rocker-crank, non-Grashof x2
CASES = [(0.04, 0.12, 0.08), (0.152, 0.198, 0.187), (0.093, 0.052, 0.081), (0.09, 0.1, 0.03),
         (0.02, 0.16, 0.075), (0.152, 0.117, 0.187)]


def _identified(args):
    mech = screwkin.load(FAMILY, args=dict(args, ground=0.1))
    q = mech.generic_configurations()[1][0]
    return mech, q, identify(mech, mech.topology(q), q, "crank_joint")


def _swept(mech, q, info, steps=4000):
    """The transmission angle at every step of sweep's motion from q over the input's whole motion (a
    turn, or both ways to the limit positions, which sweep locates and stops at)."""
    solver = PositionSolver(mech, ["crank_joint"])
    x0 = info.input_value
    if info.input_range is None:
        runs = [sweep(solver, "crank_joint", x0, x0 + 2 * np.pi, steps, q_start=q)]
    else:
        lo, hi = info.input_range
        runs = [sweep(solver, "crank_joint", x0, x, steps, q_start=q) for x in (hi + 0.1, lo - 0.1)]
        for r in runs:  # the limit positions stop it, located at the closed form's range ends
            assert r.stopped_at is not None and min(abs(r.stopped_at - lo), abs(r.stopped_at - hi)) < 1e-9
        # with the configurations sweep located there (mu changes like a square root next to them)
        return transmission_angles(mech, info, np.vstack([r.q for r in runs] + [lim.q for r in runs for lim in r.limits]))
    return transmission_angles(mech, info, np.vstack([r.q for r in runs]))


def test_located_range_holds_every_sampled_angle_and_is_reached():
    """Over the motion sweep follows (4,000 steps each way, on the assembled circuit), every sampled mu
    lies in the located range and the sampled extremes come close to its ends: an extreme inside the
    motion is stationary (the fine grid gets within 1e-4 deg), one at a limit position is the
    configuration sweep locates there (Brent on the dyad's discriminant: mu 0 or 180 deg to the
    square root of its round-off, 1e-3 deg)."""
    seen = set()
    for case in CASES:
        mech, q, info = _identified(dict(zip(("crank", "coupler", "rocker"), case)))
        tr = info.transmission
        mus = _swept(mech, q, info)
        assert tr.low - 1e-12 <= mus.min() and mus.max() <= tr.high + 1e-12, (case, tr)
        assert mus.min() - tr.low < np.radians(1e-3) and tr.high - mus.max() < np.radians(1e-3), (case, tr)
        assert tr.turns == (info.input_range is None)
        if tr.turns:  # both extremes inside the turn: stationary, so the fine grid gets within 1e-4 deg
            assert mus.min() - tr.low < np.radians(1e-4) and tr.high - mus.max() < np.radians(1e-4), case
            assert tr.dead_points == 0
        else:  # rocks between two limit positions: mu 0 (folded) or 180 deg (stretched) there, exactly
            assert tr.dead_points == 2 and len(tr.dead_at) == 2
            assert np.allclose(sorted(tr.dead_at), sorted(info.input_range), rtol=0, atol=1e-12)
            assert tr.low == 0.0 or tr.high == np.pi
        seen.add(info.grashof.split(":")[0])
    assert len(seen) == 5, seen


def test_crank_rocker_extremes_where_the_crank_lies_along_the_ground_line():
    """The textbook's crank-rocker: mu_min = acos((b^2 + c^2 - (g - a)^2) / 2bc) with the crank folded
    onto the ground line (phi = 0), mu_max = acos((b^2 + c^2 - (g + a)^2) / 2bc) stretched out along it
    (phi = 180 deg): z^2 = a^2 + g^2 - 2 a g cos(phi) is stationary there only.  The input values it
    gives put the crank's tip B on the line A D, at |BD| = g - a and g + a (forward kinematics)."""
    import pinocchio as pin

    g, a, b, c = 0.1, 0.04, 0.12, 0.08
    mech, q, info = _identified({"crank": a, "coupler": b, "rocker": c})
    tr = info.transmission
    assert tr.low == pytest.approx(np.arccos((b * b + c * c - (g - a) ** 2) / (2 * b * c)), abs=1e-14)
    assert tr.high == pytest.approx(np.arccos((b * b + c * c - (g + a) ** 2) / (2 * b * c)), abs=1e-14)
    assert tr.deviation == pytest.approx(np.pi / 2 - tr.low, abs=1e-15)
    solver = PositionSolver(mech, ["crank_joint"])
    data = mech.scratch_data()
    jb = mech.model.getJointId("coupler_joint")
    for x, z in ((tr.low_at[0], g - a), (tr.high_at[0], g + a)):
        qx = solver.track({"crank_joint": x}, q).q
        pin.forwardKinematics(mech.model, data, qx)
        B = data.oMi[jb].translation
        assert abs(B[1]) < 1e-12 and abs(np.hypot(B[0] - g, B[1]) - z) < 1e-12  # A at the origin, D at (g, 0)


def test_change_point_turns_with_one_dead_point():
    """s + l = p + q (ground 0.1, crank 0.05, coupler 0.125, rocker 0.075: |g - a| = |b - c|): the crank
    turns, the linkage folds flat once a turn (mu = 0 at phi = 0): one dead point, there."""
    mech, q, info = _identified({"crank": 0.05, "coupler": 0.125, "rocker": 0.075})
    tr = info.transmission
    assert info.grashof.startswith("change point") and tr.turns and tr.dead_points == 1 and tr.low == 0.0
    assert tr.dead_at == tr.low_at and len(tr.dead_at) == 1
    # where the crank lies along the ground line, towards D: phi = 0
    assert abs(np.remainder(tr.dead_at[0] - info.input_value + info.input_angle + np.pi, 2 * np.pi) - np.pi) < 1e-12


def test_slider_crank_range_against_its_sweep():
    """robots/slider_crank_offset.urdf (a = 0.05, b = 0.15, e = 0.02): the crank turns (a + e <= b);
    s = e - a sin(phi) runs over [e - a, e + a] = [-0.03, 0.07] and passes 0, so mu_max = 90 deg and
    mu_min = acos(0.07 / 0.15); a 4,000-step turn samples within 1e-5 deg of the smooth minimum and
    within a step's worth of the maximum, where |s| has a corner (|dmu/dphi| <= a / b there)."""
    mech = screwkin.load(ROBOTS / "slider_crank_offset.urdf")
    q = mech.assemble().q
    info = identify(mech, mech.topology(q), q, "crank_joint")
    tr = info.transmission
    assert tr.turns and tr.dead_points == 0
    assert tr.low == pytest.approx(np.arccos(0.07 / 0.15), abs=1e-14) and tr.high == pytest.approx(np.pi / 2, abs=1e-14)
    mus = _swept(mech, q, info)
    assert tr.low - 1e-12 <= mus.min() < tr.low + np.radians(1e-5)
    assert tr.high - (2 * np.pi / 4000) * 0.05 / 0.15 < mus.max() <= tr.high + 1e-12
    assert len(tr.high_at) == 2  # s = 0 twice a turn


def test_vectorised_forms_equal_the_scalar_ones():
    """four_bar_classes and the transmission forms over arrays give, element for element, what one
    design gives alone (the study's family path computes them over many designs at once)."""
    rng = np.random.default_rng(3)
    L = rng.uniform(0.02, 0.2, (4, 500))
    L[:, 0] = (0.1, 0.05, 0.125, 0.075)  # a change point
    codes = four_bar_classes(*L, 1e-9)
    mu = four_bar_transmission(*L, 1e-9)
    for k in range(0, 500, 37):
        assert codes[k] == four_bar_classes(*L[:, k], 1e-9)
        for arr, one in zip(mu, four_bar_transmission(*L[:, k], 1e-9)):
            assert arr[k] == one
    assert FOUR_BAR_CLASSES[codes[0]].startswith("change point")
    sc = slider_crank_transmission(np.array([0.05, 0.2]), 0.15, 0.02, 1e-9)
    assert list(sc[2]) == [True, False] and list(sc[3]) == [0, 2] and sc[0][1] == 0.0


def test_the_one_transmission_angle_from_points_and_from_lengths():
    """The point forms and the length form of mu, by hand: a four-bar with C at the origin, B on +y and D
    on +x has mu = 90 deg; with B at (-1, 1) 135 deg.  The same four-bar from its lengths: ground
    g = 3 (A = (0, 0), D = (3, 0)), input a = 4 straight up (phi = 90 deg, B = (0, 4)): z = |BD| = 5,
    and with coupler b = 4, output c = 3 the triangle BCD is 3-4-5, right-angled at C (cos mu = 0).
    A slider-crank's rod at 30 deg from the slide's normal has mu = 30 deg."""
    from screwkin.analysis.motion.transmission import four_bar_cos_mu, slide_transmission_angle, transmission_angle

    assert np.degrees(transmission_angle([0, 1], [0, 0], [1, 0])) == pytest.approx(90.0, abs=1e-12)
    assert np.degrees(transmission_angle([-1, 1, 0], [0, 0, 0], [2, 0, 0])) == pytest.approx(135.0, abs=1e-12)
    assert four_bar_cos_mu(3.0, 4.0, 4.0, 3.0, np.pi / 2) == pytest.approx(0.0, abs=1e-15)
    assert four_bar_cos_mu(3.0, 4.0, 4.0, 3.0, 0.0) == pytest.approx((16 + 9 - 1) / 24, abs=1e-15)  # z = 1
    normal = np.array([0.0, 1.0])
    rod = np.array([np.sin(np.radians(30)), np.cos(np.radians(30))])
    assert np.degrees(slide_transmission_angle([1.0, 2.0], np.array([1.0, 2.0]) + 0.3 * rod, normal)) == \
        pytest.approx(30.0, abs=1e-12)
