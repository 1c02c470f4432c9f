"""The condition number of a parallel robot's input -> output map (issue 43 item 3): Merlet's, of the Jacobian J
from the leg rates to the platform's twist (= that of J^-1, from the twist to the leg rates), homogenized by the
characteristic length L: the twist (v/L, w) at the platform frame's origin, the leg rates per L.  Checked against
J^-1 in closed form -- rows [u_i, (r_i x u_i) / L], u_i the unit leg vector, r_i the platform joint about the
platform frame's origin -- built from Pinocchio's placements of the base and platform joints (not from screwkin's
analysis), for the bundled Gough-Stewart 6-UPS and 3-RPR, at the file's configuration and at another one."""

import json

import numpy as np
import pinocchio as pin
import pytest

import screwkin
from conftest import ROBOTS, screwkin_cli
from screwkin.analysis.singularities.ellipsoids import with_input_output_condition
from screwkin.analysis.singular import classify as classify_only


def classify(mech, q, output):
    return with_input_output_condition(mech, q, classify_only(mech, q, output=output))

STEWART = ROBOTS / "gough_stewart_6ups.urdf"
RPR = ROBOTS / "planar_3rpr.urdf"


def closed_form_inverse_jacobian(mech, q, base_joints, platform_points, L, planar=False):
    """J^-1 (homogenized) at q: the legs run from the base joints' origins (Pinocchio's placements) to the platform
    points (platform-frame coordinates, from the file's loop joints; leg 1's is the platform frame's origin)."""
    model, data = mech.model, mech.model.createData()
    pin.framesForwardKinematics(model, data, q)
    M = data.oMf[model.getFrameId("platform")]
    rows = []
    for joint, b in zip(base_joints, platform_points):
        a = data.oMi[model.getJointId(joint)].translation
        r = M.rotation @ np.asarray(b, float)
        u = (M.translation + r - a) / np.linalg.norm(M.translation + r - a)
        m = np.cross(r, u) / L
        rows.append([u[0], u[1], m[2]] if planar else [*u, *m])
    return np.array(rows)


def cond(A) -> float:
    s = np.linalg.svd(A, compute_uv=False)
    return float(s[0] / s[-1])


def loop_points(mech, count):
    """Each leg's platform point in the platform frame: (0, 0, 0) for leg 1 (the tree), the loop joints' link2 xyz."""
    spec = {c.name: c for c in mech.spec.cut_joints}
    return [np.zeros(3)] + [np.asarray(spec[n].xyz2, float) for n in count]


STEWART_LOOPS = ["ball2", "ball3", "ball4", "ball5", "ball6"]
STEWART_BASE = [f"base{k}_a" for k in range(1, 7)]
LEGS = {"leg1": 0.05, "leg2": -0.04, "leg3": 0.08, "leg4": 0.0, "leg5": -0.06, "leg6": 0.1}


@pytest.fixture(scope="module")
def stewart():
    return screwkin.load(STEWART)


def test_the_stewart_platforms_condition_number_is_merlets(stewart):
    out = screwkin_cli("singularities", str(STEWART), "--output", "platform", "--json")
    assert out.returncode == 0, out.stderr
    d = json.loads(out.stdout)
    L = d["characteristic_length"]
    q = stewart.neutral()  # the file's configuration (it closes: drawn assembled)
    assert np.linalg.norm(stewart.closure.residual(q)) < 1e-9
    Jinv = closed_form_inverse_jacobian(stewart, q, STEWART_BASE, loop_points(stewart, STEWART_LOOPS), L)
    assert d["condition_input_output"] == pytest.approx(cond(Jinv), rel=1e-9)
    assert d["condition_input_output"] == pytest.approx(5.935, abs=1e-3)
    assert d["condition"] == pytest.approx(2.718, abs=1e-3)  # kept, and said what it is of
    assert d["condition_of"].startswith("J_o V")
    text = screwkin_cli("singularities", str(STEWART), "--output", "platform").stdout
    assert f"condition number of the input -> output map (Merlet's): {d['condition_input_output']:.4g}" in text
    assert f"condition number {d['condition']:.4g}" in text and "of J_o V" in text


def test_the_stewart_platform_elsewhere(stewart):
    idx = stewart.velocity_indices(list(LEGS))
    q0 = stewart.neutral()
    q0[[stewart.model.joints[stewart.model.getJointId(n)].idx_q for n in LEGS]] = list(LEGS.values())
    q = stewart.assemble(q0, frozen=idx).q
    rep = classify(stewart, q, output="platform")
    Jinv = closed_form_inverse_jacobian(stewart, q, STEWART_BASE, loop_points(stewart, STEWART_LOOPS), rep.length)
    assert rep.condition_input_output == pytest.approx(cond(Jinv), rel=1e-8)
    assert rep.condition_input_output != pytest.approx(rep.condition, rel=0.1)  # two different numbers


def test_the_3rpr_condition_number_is_merlets():
    mech = screwkin.load(RPR)
    q = mech.neutral()
    rep = classify(mech, q, output="platform")
    Jinv = closed_form_inverse_jacobian(mech, q, ["base1", "base2", "base3"], loop_points(mech, ["wrist2", "wrist3"]),
                                        rep.length, planar=True)
    assert rep.condition_input_output == pytest.approx(cond(Jinv), rel=1e-9)
    assert rep.input_output_note is None


def test_without_an_output_it_says_to_give_one():
    out = screwkin_cli("singularities", str(STEWART), "--json")
    d = json.loads(out.stdout)
    assert d["condition_input_output"] is None and "--output" in d["condition_input_output_note"]
    assert d["condition"] is not None and d["condition_of"].startswith("K_p")


def test_near_an_actuator_singularity_only_merlets_number_says_so(stewart):
    """The issue's case: the platform turned 80 deg about the vertical through its centre (towards Fichter's
    singularity), legs set to the lengths of that pose: the actuator's relative sigma_min is small and Merlet's
    condition number large (closed form), while the condition number of J_o V stays near 3."""
    model, data = stewart.model, stewart.model.createData()
    q = stewart.neutral()
    pin.framesForwardKinematics(model, data, q)
    M0 = data.oMf[model.getFrameId("platform")]
    points = loop_points(stewart, STEWART_LOOPS)
    base = [data.oMi[model.getJointId(j)].translation.copy() for j in STEWART_BASE]
    drawn = [M0.act(b) for b in points]
    centre = np.mean(drawn, axis=0)
    R = pin.utils.rpyToMatrix(0.0, 0.0, np.radians(80.0))
    legs = {f"leg{k + 1}": np.linalg.norm(centre + R @ (b - centre) - a) - np.linalg.norm(b - a)
            for k, (a, b) in enumerate(zip(base, drawn))}
    q0 = stewart.neutral()
    q0[[model.joints[model.getJointId(n)].idx_q for n in legs]] = list(legs.values())
    q = stewart.assemble(q0, frozen=stewart.velocity_indices(list(legs))).q
    rep = classify(stewart, q, output="platform")
    Jinv = closed_form_inverse_jacobian(stewart, q, STEWART_BASE, points, rep.length)
    assert rep.condition_input_output == pytest.approx(cond(Jinv), rel=1e-8)
    assert rep.condition_input_output > 100 and rep.condition < 3 and rep.sigmas["actuator"] < 0.01
