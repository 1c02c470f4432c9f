"""``solve --all --connect`` and ``ik --all --connect`` (issue 44): which listed modes a path joins without a
singularity.  Checked against independent computations: the 3-RPR of Innocenti & Parenti-Castelli (Zein,
Wenger & Chablat 2008; tests/loci_robots.py) whose leg lengths and leg-line Jacobian are computed here with
numpy from the platform's pose, a five-bar's tip against the line of its elbows (Pinocchio's placements), and
a 6R arm's det J from Pinocchio."""

import json

import numpy as np
import pinocchio as pin
import pytest
from conftest import ROBOTS, screwkin_cli
from loci_robots import RPR_BASE, RPR_PLATFORM, rpr3, rpr3_polynomial

import screwkin

#: leg lengths [m] 4 mm from the cusp at (rho2, rho3) = (0.18080, 0.31502) of the section rho1 = 0.17 (the one
#: test_loci.py locates as a triple root of the forward-kinematics polynomial), inside its wedge: four real
#: assembly modes, three of them the cusp's
RHO = (0.17, 0.18194089, 0.31226874)


def _rpr_geometry(text, rho0, joints):
    """From the platform's pose alone -- B1 at the end of leg 1 (its base joint's turn of the drawn direction,
    length rho0 + leg1), the platform turned by base1 + wrist1 from its drawn 30 deg -- the three leg lengths
    |B_i - A_i| (plain numpy distances) and det of the leg-line Jacobian [d_i, (B_i - B1) x d_i]."""
    u0 = np.array([float(v) for v in text.split('name="leg1"')[1].split('axis xyz="')[1].split('"')[0].split()[:2]])
    c, s = np.cos(joints["base1"]), np.sin(joints["base1"])
    B1 = RPR_BASE[0] + (rho0[0] + joints["leg1"]) * np.array([c * u0[0] - s * u0[1], s * u0[0] + c * u0[1]])
    phi = np.radians(30.0) + joints["base1"] + joints["wrist1"]
    R = np.array([[np.cos(phi), -np.sin(phi)], [np.sin(phi), np.cos(phi)]])
    B = [B1 + R @ (RPR_PLATFORM[i] - RPR_PLATFORM[0]) for i in range(3)]
    lengths = np.array([np.linalg.norm(B[i] - RPR_BASE[i]) for i in range(3)])
    rows = []
    for i in range(3):
        d = (B[i] - RPR_BASE[i]) / lengths[i]
        b = B[i] - B1
        rows.append([d[0], d[1], b[0] * d[1] - b[1] * d[0]])
    return lengths, np.linalg.det(np.array(rows))


def test_connect_needs_all():
    p = screwkin_cli("solve", str(ROBOTS / "five_bar.urdf"), "--set", "motor1=0.3,motor2=-0.2", "--connect")
    assert p.returncode == 2 and "--all" in p.stderr and len(p.stderr.strip().splitlines()) == 1
    p = screwkin_cli("ik", str(ROBOTS / "arm_6r.urdf"), "--output", "flange", "--pose", "0.4 0.1 0.3 0 1.57 0",
                     "--connect")
    assert p.returncode == 2 and "--all" in p.stderr and "Traceback" not in p.stderr


def test_five_bar_modes_have_opposite_det_signs_and_the_tip_opposite_sides(tmp_path):
    """A five-bar's two assembly modes (the tip on either side of the line of the elbows B1 B2, the direct
    kinematics a quadratic) can only meet where the distal links are collinear: reported not joined, proved,
    with the det reason; the sides from Pinocchio's placements."""
    path = ROBOTS / "five_bar.urdf"
    p = screwkin_cli("solve", str(path), "--set", "motor1=0.3,motor2=-0.2", "--all", "--connect", "--json")
    assert p.returncode == 0, p.stderr
    d = json.loads(p.stdout)
    assert len(d["solutions"]) == 2 and sorted(d["det_signs"]) == [-1, 1]
    (c,) = d["connections"]
    assert c["modes"] == [1, 2] and c["joined"] is False and c["proved"] is True and "opposite signs" in c["why"]
    assert c["path"] == [] and set(c) >= {"modes", "joined", "why", "path"}
    mech = screwkin.load(path)
    model, data = mech.model, mech.model.createData()
    sides = []
    for sol in d["solutions"]:
        q = _q_of(mech, sol["joints"])
        pin.framesForwardKinematics(model, data, q)
        B1, B2, P = (data.oMf[model.getFrameId(n)].translation[:2] for n in ("distal1", "distal2", "tip"))
        e, f = B2 - B1, P - B1
        sides.append(np.sign(e[0] * f[1] - e[1] * f[0]))
    assert sides[0] == -sides[1]


def _q_of(mech, joints):
    q = mech.neutral()
    for name, v in joints.items():
        if name in mech.coordinate_names:
            c = mech.coordinate(name)
            if c.nq == 2:
                q[c.idx_q] = [np.cos(v), np.sin(v)]
            else:
                q[c.idx_q] = v
    return q


def test_ik_connect_det_signs_are_pinocchios():
    """ik --all --connect of a 6R arm: a pair is said proved apart exactly where det J (Pinocchio's 6 x 6 frame
    Jacobian, computed here) has opposite signs; the same-sign pairs are said unknown, not joined."""
    path = ROBOTS / "arm_6r.urdf"
    p = screwkin_cli("ik", str(path), "--output", "flange", "--pose", "0.4 0.1 0.3 0 1.57 0", "--all", "--connect",
                     "--json")
    assert p.returncode == 0, p.stderr
    d = json.loads(p.stdout)
    mech = screwkin.load(path)
    model, data = mech.model, mech.model.createData()
    fid = model.getFrameId("flange")
    signs = []
    for sol in d["solutions"]:
        q = _q_of(mech, sol["joints"])
        J = pin.computeFrameJacobian(model, data, q, fid, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
        signs.append(np.sign(np.linalg.det(J)))
    n = len(d["solutions"])
    assert n >= 2 and len(d["connections"]) == n * (n - 1) // 2
    for c in d["connections"]:
        i, j = (k - 1 for k in c["modes"])
        assert c["joined"] is False and c["path"] == []
        assert c["proved"] == (signs[i] != signs[j]), c
        assert ("opposite signs" in c["why"]) == (signs[i] != signs[j])


@pytest.mark.slow
def test_3rpr_modes_of_the_same_sign_joined_round_a_cusp(tmp_path):
    """solve --all --connect of the Innocenti 3-RPR 4 mm from a cusp: four modes (the real roots of the
    independent polynomial); the two outer modes of the cusp, of the same det sign, joined by a loop of leg2 and
    leg3 -- along the whole path the legs computed from the platform's pose are the inputs, the leg-line det
    keeps its sign and stays away from zero, the ends are the two listed modes; every pair of opposite signs
    (of the independent det) reported not joined with the det reason; --animate writes the path."""
    text, rho0 = rpr3()
    path = tmp_path / "rpr3.urdf"
    path.write_text(text)
    roots = rpr3_polynomial(RHO).roots()
    assert sum(abs(r.imag) < 1e-9 for r in roots) == 4
    values = ",".join(f"leg{i + 1}={float(RHO[i] - rho0[i])!r}" for i in range(3))
    gif = tmp_path / "connect.gif"
    p = screwkin_cli("solve", str(path), "--set", values, "--all", "--connect", "--json", "--animate", str(gif),
                     timeout=900)
    assert p.returncode == 0, p.stderr
    d = json.loads(p.stdout)
    sols = d["solutions"]
    assert len(sols) == 4
    dets = [_rpr_geometry(text, rho0, s["joints"])[1] for s in sols]
    assert len(d["connections"]) == 6
    joined = [c for c in d["connections"] if c["joined"]]
    assert len(joined) == 1
    for c in d["connections"]:
        i, j = (k - 1 for k in c["modes"])
        if np.sign(dets[i]) != np.sign(dets[j]):
            assert not c["joined"] and c["proved"] and "det J of opposite signs" in c["why"] and c["path"] == []
        elif not c["joined"]:
            assert c["proved"] is False and "not proved impossible" in c["why"]
    c = joined[0]
    i, j = (k - 1 for k in c["modes"])
    assert np.sign(dets[i]) == np.sign(dets[j])
    assert c["sigma_min"] > 1e-4 and set(c["plane"]) == {"leg2", "leg3"}
    assert 50 <= len(c["path"]) <= 100
    sign = np.sign(dets[i])
    for point in c["path"]:
        joints = point["joints"]
        lengths, det = _rpr_geometry(text, rho0, joints)
        given = [rho0[k] + joints[f"leg{k + 1}"] for k in range(3)]
        assert np.allclose(lengths, given, rtol=0, atol=1e-9)  # the legs close
        assert abs(given[0] - RHO[0]) < 1e-12  # leg1 held
        assert np.sign(det) == sign and abs(det) > 1e-4
    for end, k in ((c["path"][0], i), (c["path"][-1], j)):
        for name, v in end["joints"].items():
            v = sols[k]["joints"][name]
            assert abs(end["joints"][name] - v) < 1e-6, (name, end["joints"][name], v)
    assert d["animation"]["modes"] == c["modes"] and gif.read_bytes()[:6] == b"GIF89a"


def _o3r_point(params, th):
    """The orthogonal 3R's tool point by plain numpy from the URDF's frames (tests/loci_robots.orthogonal_3r):
    Rz(theta1), then (d2, 0, 0) rolled -90 deg, Rz(theta2), then (d3, 0, r2) rolled 90 deg, Rz(theta3), the point
    (d4, 0, r3)."""
    d2, d3, d4, r2, r3 = params

    def rz(t):
        c, s = np.cos(t), np.sin(t)
        return np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]])

    def fixed(xyz, roll):
        c, s = np.cos(roll), np.sin(roll)
        return np.array([[1, 0, 0, xyz[0]], [0, c, -s, xyz[1]], [0, s, c, xyz[2]], [0, 0, 0, 1.0]])

    T = rz(th[0]) @ fixed((d2, 0, 0), -np.pi / 2) @ rz(th[1]) @ fixed((d3, 0, r2), np.pi / 2) @ rz(th[2])
    return (T @ np.array([d4, 0, r3, 1.0]))[:3]


def _o3r_det(params, th, h=1e-6):
    J = np.column_stack([(_o3r_point(params, th + h * e) - _o3r_point(params, th - h * e)) / (2 * h)
                         for e in np.eye(3)])
    return np.linalg.det(J)


@pytest.mark.slow
def test_ik_connect_joins_two_solutions_of_a_cuspidal_3r(tmp_path):
    """The cuspidal orthogonal 3R of test_loci.py (d2 = 1, d3 = 2, d4 = 1.5, r2 = 1, r3 = 0; Baili, Wenger &
    Chablat), its tool point 0.1 m from a cusp of the section y = 0, inside the cusp's wedge: four solutions,
    each tan(theta3 / 2) a real root of the independent quartic; a pair of the same sign of det J (numpy finite
    differences of the numpy forward kinematics) joined by a joint path whose tool point stays in the section,
    leaves the target and comes back, det J keeping its sign away from zero; pairs of opposite signs proved apart."""
    from loci_robots import orthogonal_3r, orthogonal_3r_quartic

    params = (1.0, 2.0, 1.5, 1.0, 0.0)
    path = tmp_path / "o3r.urdf"
    path.write_text(orthogonal_3r(*params))
    target = np.array([1.45208637, 0.0, 0.47878859])
    p = screwkin_cli("ik", str(path), "--output", "tool", "--position", ",".join(repr(float(v)) for v in target),
                     "--all", "--connect", "--json", timeout=900)
    assert p.returncode == 0, p.stderr
    d = json.loads(p.stdout)
    roots = orthogonal_3r_quartic(*params, target[0], target[2]).roots()
    real = np.sort(roots[abs(roots.imag) < 1e-9].real)
    assert len(real) == 4 and len(d["solutions"]) == 4
    th = [np.array([s["joints"][f"theta{k}"] for k in (1, 2, 3)]) for s in d["solutions"]]
    for t in th:
        assert np.abs(real - np.tan(t[2] / 2)).min() < 1e-6
        assert np.allclose(_o3r_point(params, t), target, atol=1e-9)
    dets = [_o3r_det(params, t) for t in th]
    joined = [c for c in d["connections"] if c["joined"]]
    assert len(joined) >= 1
    for c in d["connections"]:
        i, j = (k - 1 for k in c["modes"])
        if np.sign(dets[i]) != np.sign(dets[j]):
            assert not c["joined"] and c["proved"] and "det J of opposite signs" in c["why"]
    for c in joined:
        i, j = (k - 1 for k in c["modes"])
        assert np.sign(dets[i]) == np.sign(dets[j]) and c["sigma_min"] > 1e-4
        pts = [np.array([pt["joints"][f"theta{k}"] for k in (1, 2, 3)]) for pt in c["path"]]
        assert np.allclose(pts[0], th[i], atol=1e-6) and np.allclose(pts[-1], th[j], atol=1e-6)
        tool = np.array([_o3r_point(params, t) for t in pts])
        assert np.abs(tool[:, 1]).max() < 1e-9  # in the section y = 0
        assert np.linalg.norm(tool - target, axis=1).max() > 0.05  # it leaves the target and comes back
        for t in pts:
            assert np.sign(_o3r_det(params, t)) == np.sign(dets[i]) and abs(_o3r_det(params, t)) > 1e-3
