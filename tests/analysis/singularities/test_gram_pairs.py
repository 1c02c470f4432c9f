"""The numeric Gram cofactors of loops through rolling and gear pairs (issue 25, points 5 and 6): the
pair is one column, a revolute about the plane's normal through the contact point (pure rolling turns
one link about it relative to the other), as singularities --symbolic takes it.  Against formulas the
test writes itself from the files' dimensions (the symbolic ones of tests/analysis/course/test_course_rolling.py, with
numbers put in).  The numeric table is dimensionless: twists (y/L, -x/L, 1) of revolutes, a slide's
(cos b, sin b, 0) (linear part / L, column x L), so each hand formula is written with every length over L."""

import json

import numpy as np
import pytest

from screwkin import load
from screwkin.analysis.position.position import PositionSolver
from screwkin.analysis.singular import classify, gram_cofactors
from screwkin.cli import main

WHEELS, RACK, GEARS = "robots/friction_wheels.urdf", "robots/rack_pinion.urdf", "robots/gear_train_idler.urdf"
# friction_wheels.urdf: disc 2 (radius 0.02) pinned at the origin, its centre at (0.008, 0.008) at theta2 = 0;
# disc 3 (radius 0.01) on a slider along x through the origin
R2, R3 = 0.02, 0.01


def solved(path, name, value):
    mech = load(path)
    q0 = mech.generic_configurations()[0].q
    res = PositionSolver(mech, [name]).solve({name: value}, near=mech.joint_values(q0))
    return mech, res.solutions[0].q


def wheels_by_hand(theta2, L):
    """The friction wheels' cofactors at theta2: C2 = |O2C2| (cos, sin)(theta2 + 45 deg), disc 3's centre at
    x4 = C2x + sqrt((R2 + R3)^2 - C2y^2) (the branch drawn), t the line of centres' angle; the symbolic formulas
    C_wheel2 = rho3^2 cos^2 t, C_slide = rho3^2 x4^2 sin^2 t, C_wheel3 = (x4 - rho3 cos t)^2, C_wheels = x4^2
    (derived in tests/analysis/course/test_course_rolling.py) with lengths over L."""
    c2 = np.hypot(0.008, 0.008) * np.array([np.cos(theta2 + np.pi / 4), np.sin(theta2 + np.pi / 4)])
    x4 = c2[0] + np.sqrt((R2 + R3) ** 2 - c2[1] ** 2)
    t = np.arctan2(-c2[1], x4 - c2[0])
    rho3, x = R3 / L, x4 / L
    return x4, {"wheel2_joint": rho3 ** 2 * np.cos(t) ** 2, "slide": rho3 ** 2 * x ** 2 * np.sin(t) ** 2,
                "wheel3_joint": (x - rho3 * np.cos(t)) ** 2, "wheels": x ** 2}


@pytest.mark.parametrize("deg", [0.0, 30.0, 100.0, -160.0])
def test_friction_wheels_numeric_cofactors_are_the_symbolic_formulas(deg):
    mech, q = solved(WHEELS, "wheel2_joint", np.radians(deg))
    (g,) = gram_cofactors(mech, q)
    x4, hand = wheels_by_hand(np.radians(deg), mech.length)
    slide = mech.coordinate("slide")
    assert 0.0369136645896019 + q[slide.idx_q] == pytest.approx(x4, abs=1e-9)  # the configuration meant
    assert g.nullity == 1 and g.note is None
    assert sorted(g.joints) == sorted(hand)  # one column for the pair, its virtual joints gone
    for joint, value in hand.items():
        assert g.cofactors[joint] == pytest.approx(value, rel=1e-7, abs=1e-12), joint
    assert g.zero == ()
    assert classify(mech, q).stationary_joints == ()


def test_friction_wheels_stationary_slider_where_its_cofactor_vanishes(capsys):
    """At theta2 = -45 deg disc 2's centre is on the slider's line: sin t = 0, so C_slide = rho3^2 x4^2 sin^2 t = 0;
    stationary joints names the slide and only it, as the Gram table does."""
    mech, q = solved(WHEELS, "wheel2_joint", np.radians(-45.0))
    (g,) = gram_cofactors(mech, q)
    _, hand = wheels_by_hand(np.radians(-45.0), mech.length)
    assert hand["slide"] < 1e-30
    assert g.zero == ("slide",)
    assert abs(g.cofactors["slide"]) < 1e-12
    for joint in ("wheel2_joint", "wheel3_joint", "wheels"):
        assert g.cofactors[joint] == pytest.approx(hand[joint], rel=1e-7)
    assert classify(mech, q).stationary_joints == ("slide",)
    assert main(["singularities", WHEELS, "--set", "wheel2_joint=-45deg", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["stationary_joints"] == ["slide"] and d["gram_zero"] == ["slide"]
    assert main(["singularities", WHEELS]) == 0
    out = capsys.readouterr().out
    assert "not computed" not in out and "wheels" in out


@pytest.mark.parametrize("deg", [0.0, 40.0, -170.0])
def test_gear_loops_numeric_cofactors_are_the_hand_gram_determinants(deg):
    """gear_train_idler.urdf: input (pitch radius 0.05) at the origin, idler (0.03) 0.08 m and output (0.08) 0.19 m
    along x.  A loop of two gears on one frame: twists (0, -x/L, 1) of the two centres and of the contact, each
    2 x 2 Gram determinant |O_b - P|^2 / L^2 (the points on the x axis through the origin): removing one gear
    leaves the other's centre and the contact, removing the pair leaves the centre distance."""
    mech, q = solved(GEARS, "input_joint", np.radians(deg))
    L = mech.length
    loops = {g.loop: g for g in gram_cofactors(mech, q)}
    hand = {"mesh1": {"input_joint": 0.03, "idler_joint": 0.05, "mesh1": 0.08},
            "mesh2": {"idler_joint": 0.08, "output_joint": 0.03, "mesh2": 0.11}}
    assert set(loops) == set(hand)
    for name, cof in hand.items():
        g = loops[name]
        assert g.nullity == 1 and sorted(g.joints) == sorted(cof)
        for joint, d in cof.items():
            assert g.cofactors[joint] == pytest.approx((d / L) ** 2, rel=1e-9), (name, joint)
        assert g.zero == ()
    assert classify(mech, q).stationary_joints == ()


@pytest.mark.parametrize("deg", [0.0, 50.0, -300.0])
def test_rack_loop_numeric_cofactors_are_the_hand_formulas(deg):
    """rack_pinion.urdf: the pinion (pitch radius 0.04) at the origin, the rack's pitch line at y = 0.04: the contact
    stays at (0, 0.04) however far the rack has moved.  Twists (0, 0, 1), (1, 0, 0), (0.04/L, 0, 1): C_pinion =
    |(1,0,0) x (0.04/L, 0, 1)|^2 = 1, C_rack = (0.04/L)^2, C_mesh = 1 (the symbolic 1, rho2^2, 1 over L)."""
    mech, q = solved(RACK, "pinion_joint", np.radians(deg))
    rack = mech.coordinate("rack_joint")
    assert abs(q[rack.idx_q]) == pytest.approx(0.04 * abs(np.radians(deg)), abs=1e-9)  # the rack has moved
    (g,) = gram_cofactors(mech, q)
    assert g.nullity == 1 and sorted(g.joints) == ["mesh", "pinion_joint", "rack_joint"]
    hand = {"pinion_joint": 1.0, "rack_joint": (0.04 / mech.length) ** 2, "mesh": 1.0}
    for joint, value in hand.items():
        assert g.cofactors[joint] == pytest.approx(value, rel=1e-9), joint


def test_a_loop_through_a_sliding_contact_says_why_it_is_not_computed():
    """A cam or pin-in-slot contact has two freedoms (rolling and sliding): no one-twist equivalent."""
    from conftest import ROBOTS
    paths = [p for p in sorted(ROBOTS.glob("*.urdf")) if 'type="contact"' in p.read_text()]
    assert paths
    mech = load(str(paths[0]))
    q = mech.generic_configurations()[0].q
    notes = [g.note for g in gram_cofactors(mech, q) if g.nullity == -1]
    assert notes and all("sliding contact" in n and "not computed" in n for n in notes)


PINION_ON_A_SLIDE = """<?xml version="1.0"?>
<robot name="pinion_on_a_slide">
  <link name="ground"/><link name="carriage"/><link name="pinion"/>
  <joint name="carriage_joint" type="prismatic">
    <parent link="ground"/><child link="carriage"/><origin xyz="0 0 0" rpy="0 0 0"/><axis xyz="1 0 0"/>
    <limit lower="-0.2" upper="0.2" effort="10" velocity="5"/>
  </joint>
  <joint name="pinion_joint" type="continuous">
    <parent link="carriage"/><child link="pinion"/><origin xyz="0 0 0" rpy="0 0 0"/><axis xyz="0 0 1"/>
  </joint>
  <loop_joint name="mesh" type="gear">
    <link1 link="ground" xyz="0 0.04 0" rpy="0 0 0"/>
    <link2 link="pinion" xyz="0 0 0" rpy="0 0 1.5707963267949"/>
    <axis xyz="0 0 1"/>
    <gear radius1="inf" radius2="0.04"/>
  </loop_joint>
  <transmission name="t"><joint name="carriage_joint"/></transmission>
</robot>
"""


@pytest.mark.parametrize("s", [0.0, 0.07, -0.03])
def test_pinion_on_a_slide_rolls_on_a_fixed_rack_about_the_moving_contact(tmp_path, s):
    """A pinion (pitch radius 0.04) on a carriage sliding along x, meshing with a fixed rack whose pitch line is
    y = 0.04: the contact is (s, 0.04), above the pinion's centre (s, 0), wherever the carriage is.  Twists, lengths
    over L: slide (1, 0, 0), pinion (0, -s', 1), mesh (h, -s', 1) with s' = s/L, h = 0.04/L:
    C_slide = |pinion x mesh|^2 = h^2 (1 + s'^2), C_pinion = |slide x mesh|^2 = 1 + s'^2, C_mesh = 1 + s'^2."""
    path = tmp_path / "pinion_on_a_slide.urdf"
    path.write_text(PINION_ON_A_SLIDE)
    mech, q = solved(str(path), "carriage_joint", s)
    (g,) = gram_cofactors(mech, q)
    L = mech.length
    sp, h = s / L, 0.04 / L
    assert g.nullity == 1 and sorted(g.joints) == ["carriage_joint", "mesh", "pinion_joint"]
    hand = {"carriage_joint": h ** 2 * (1 + sp ** 2), "pinion_joint": 1 + sp ** 2, "mesh": 1 + sp ** 2}
    for joint, value in hand.items():
        assert g.cofactors[joint] == pytest.approx(value, rel=1e-9), joint


@pytest.mark.parametrize("deg", [0.0, 720.0])
def test_screw_pair_loop_is_one_screw_column(deg):
    """lead_screw_jack.urdf: screw, lift and the screw pair of lead 0.005 m all on the z axis through the origin.
    Twists (0, 0, 0, 0, 0, 1), the slide's (0, 0, 1, 0, 0, 0) and the screw's (0, 0, h/L, 0, 0, 1), h = lead / 2 pi:
    C_screw = Gram(lift, thread) = 1 (h^2/L^2 + 1) - (h/L)^2 = 1, C_lift = Gram(screw, thread) = (h/L)^2,
    C_thread = Gram(screw, lift) = 1."""
    mech, q = solved("robots/lead_screw_jack.urdf", "screw_joint", np.radians(deg))
    (g,) = gram_cofactors(mech, q)
    h = 0.005 / (2 * np.pi) / mech.length
    assert g.nullity == 1 and sorted(g.joints) == ["lift", "screw_joint", "thread"]
    for joint, value in {"screw_joint": 1.0, "lift": h ** 2, "thread": 1.0}.items():
        assert g.cofactors[joint] == pytest.approx(value, rel=1e-9), joint


def test_pair_rate_is_the_relative_turning_and_the_gram_null_vector_agrees():
    """The pair's column turns at the links' relative rate: for the friction wheels theta3' - theta2' (disc 3 rides a
    slider that does not turn), the rates here by central differences of solved configurations; the loop's null
    vector v (adj G = c v v^T) has v_wheels / v_wheel2 = the same rate over theta2'."""
    import pinocchio as pin
    from screwkin.analysis.singular import loop_twists, pair_rate
    from screwkin.model.state import KinematicState
    t, dt = np.radians(30.0), 1e-6
    mech, q = solved(WHEELS, "wheel2_joint", t)
    _, qa = solved(WHEELS, "wheel2_joint", t - dt)
    _, qb = solved(WHEELS, "wheel2_joint", t + dt)
    qd = pin.difference(mech.model, qa, qb) / (2 * dt)
    w2, w3 = (qd[mech.coordinate(n).idx_v] for n in ("wheel2_joint", "wheel3_joint"))
    assert w2 == pytest.approx(1.0, abs=1e-6)
    (cut,) = mech.cuts
    rate = pair_rate(mech, cut, KinematicState(mech, q, qd))
    assert rate == pytest.approx(w3 - w2, rel=1e-5)
    names, S, _ = loop_twists(mech, q, cut)
    v = np.linalg.svd(S)[2][-1]
    assert v[names.index("wheels")] / v[names.index("wheel2_joint")] == pytest.approx(rate / w2, rel=1e-5)
