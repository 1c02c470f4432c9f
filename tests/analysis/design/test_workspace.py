"""screwkin workspace (issue 16 part 1) against closed forms computed here:

- five-bar: the tip P (distal links' common pin) reaches the intersection of two annuli
  (radii |l1 - l2| .. l1 + l2 about each base pivot), area by the circle-lens formula;
- Delta (passive limits opened so that only the motors' limits bound it): the platform reaches
  the points where each arm's closed-form inverse kinematics has a solution within +-1.5 rad;
  volume by Monte Carlo on that closed form, and every reached grid point checked against it;
- planar 2R arm (grid) and spatial 3R elbow arm (sampling): an annulus and a spherical shell.
Also the batched closure rows against ClosureSystem's, the IK of a geared mechanism, and the
CLI's outputs and one-line errors."""

import json

import numpy as np
import pinocchio as pin
import pytest
from conftest import ROBOTS, screwkin_cli

import screwkin
from screwkin.model.kernel.stacks import BatchClosure
from screwkin.analysis.position.ik import inverse_kinematics
from screwkin.analysis.design.workspace import workspace
from screwkin.errors import UsageError


def lens(r1, r2, d):
    """Area common to two discs of radii r1, r2 whose centres are d apart."""
    if d >= r1 + r2:
        return 0.0
    if d <= abs(r1 - r2):
        return np.pi * min(r1, r2) ** 2
    a1 = r1 * r1 * np.arccos((d * d + r1 * r1 - r2 * r2) / (2 * d * r1))
    a2 = r2 * r2 * np.arccos((d * d + r2 * r2 - r1 * r1) / (2 * d * r2))
    return a1 + a2 - 0.5 * np.sqrt((-d + r1 + r2) * (d + r1 - r2) * (d - r1 + r2) * (d + r1 + r2))


# ---------------------------------------------------------------------------------- five-bar
def test_five_bar_area_is_the_annuli_intersection():
    # robots/five_bar.urdf: base pivots 0.1 m apart, proximal 0.15 m, distal 0.1 m, so P lies
    # within 0.05..0.25 m of both pivots; the motors turn fully and the passive joints too
    R, r, d = 0.25, 0.05, 0.1
    exact = lens(R, R, d) - 2 * lens(r, R, d) + lens(r, r, d)
    m = screwkin.load(ROBOTS / "five_bar.urdf")
    res = workspace(m, "tip", point=True, resolution=0.005)
    assert res.dimension == 2 and res.method == "grid"
    assert res.volume == pytest.approx(exact, rel=3e-3)  # measured: 0.1307 against 0.13098
    assert res.volume_cells == pytest.approx(exact, rel=1e-2)
    # every reached point is in both annuli (up to the solver's closure tolerance)
    pivots = np.array([[0.0, 0.0], [0.1, 0.0]])
    xy = res.positions[:, :2]
    for c in pivots:
        dist = np.linalg.norm(xy - c, axis=1)
        assert dist.min() >= r - 1e-9 and dist.max() <= R + 1e-9
    # and the configurations place the tip there
    fid = m.link_frame("tip")
    for k in np.random.default_rng(0).choice(len(res.positions), 20, replace=False):
        pin.framesForwardKinematics(m.model, m.data, res.configurations[k])
        assert np.allclose(m.data.oMf[fid].translation, res.positions[k], atol=1e-9)
    # the boundary points lie on the circles
    b = res.boundary[:, :2]
    on = np.min(np.abs(np.stack([np.linalg.norm(b - c, axis=1) - rad for c in pivots for rad in (r, R)])), axis=0)
    assert np.percentile(on, 95) < res.resolution / 16


def test_five_bar_distal_link_moves_over_no_area_at_a_constant_orientation():
    m = screwkin.load(ROBOTS / "five_bar.urdf")
    # the distal link turns as P moves: asked without --point, the answer is P's workspace, said so
    res = workspace(m, "tip", resolution=0.02)
    assert res.point and "as --point" in res.notes[0]
    with pytest.raises(UsageError, match="curve"):
        workspace(m, "tip", orientation=np.eye(3), resolution=0.02)


# ------------------------------------------------------------------------------------- Delta
R_BASE, R_PLAT, ARM, ROD, LIMIT = 0.15, 0.04, 0.2, 0.4, 1.5  # robots/delta_parallelogram.urdf


def delta_reachable(C):
    """Closed-form inverse kinematics of the Delta: platform centres C (N, 3) whose three arms
    all have a solution within the motors' limits (the elbow-out branch of the file)."""
    ok = np.ones(len(C), bool)
    for g in np.radians([0, 120, 240]):
        c, s = np.cos(g), np.sin(g)
        x, y, z = c * C[:, 0] + s * C[:, 1], -s * C[:, 0] + c * C[:, 1], C[:, 2]
        A = R_BASE - R_PLAT - x
        P, Q = 2 * ARM * A, 2 * ARM * z
        D = ROD**2 - A * A - y * y - z * z - ARM**2
        n = np.hypot(P, Q)
        ok &= np.abs(D) <= n
        phi = np.arctan2(Q, P) + np.arccos(np.clip(D / n, -1, 1))
        theta = (phi - np.radians(30) + np.pi) % (2 * np.pi) - np.pi  # the arm is 30 deg down at 0
        ok &= np.abs(theta) <= LIMIT
    return ok


@pytest.fixture(scope="module")
def delta(tmp_path_factory):
    text = (ROBOTS / "delta_parallelogram.urdf").read_text()
    text = text.replace('lower="-1.2" upper="1.2"', 'lower="-3.1416" upper="3.1416"')  # rods' spherical joints
    path = tmp_path_factory.mktemp("delta") / "delta_free.urdf"
    path.write_text(text)
    m = screwkin.load(path)
    return m, workspace(m, "platform", point=True, resolution=0.04)


def test_delta_volume_against_monte_carlo_on_the_closed_form(delta):
    m, res = delta
    rng = np.random.default_rng(1)
    lo, hi = np.array([-0.6, -0.6, -0.75]), np.array([0.6, 0.6, 0.1])
    N = 1_000_000
    f = delta_reachable(rng.uniform(lo, hi, size=(N, 3))).mean()
    box = np.prod(hi - lo)
    V, sd = box * f, box * np.sqrt(f * (1 - f) / N)  # measured 0.11186 +- 0.00035 (0.3 %)
    assert abs(res.volume - V) < 4 * sd + 0.005 * V  # grid 0.11192 at h = 0.04
    assert res.dimension == 3 and not res.truncated


def test_delta_reached_points_satisfy_the_closed_form(delta):
    m, res = delta
    q = m.generic_configurations()[0].q
    pin.framesForwardKinematics(m.model, m.data, q)
    # the platform frame's origin sits off the platform's centre (0, 0, z) at rest
    offset = m.data.oMf[m.link_frame("platform")].translation.copy()
    offset[2] = 0.0
    assert delta_reachable(res.positions - offset).all()
    # and grid points one step outside the reached set are mostly out of reach (the boundary is
    # located: points beyond it by more than a step are not reachable)
    outside = res.boundary
    centre = res.positions.mean(axis=0)
    away = outside + 2 * res.resolution * (outside - centre) / np.linalg.norm(outside - centre, axis=1)[:, None]
    assert delta_reachable(away - offset).mean() < 0.2
    assert 0 < res.free_volume < res.volume


# ------------------------------------------------------------------------------- serial arms
ARM_2R = """<robot name="arm2r">
  <link name="base"/><link name="upper"/><link name="fore"/><link name="hand"/>
  <joint name="shoulder" type="continuous"><parent link="base"/><child link="upper"/>
    <axis xyz="0 0 1"/></joint>
  <joint name="elbow" type="revolute"><parent link="upper"/><child link="fore"/>
    <origin xyz="{l1} 0 0"/><axis xyz="0 0 1"/><limit lower="-3.14159" upper="3.14159" effort="1" velocity="1"/></joint>
  <joint name="wrist" type="fixed"><parent link="fore"/><child link="hand"/><origin xyz="{l2} 0 0"/></joint>
</robot>"""

ARM_3R = """<robot name="elbow3r">
  <link name="base"/><link name="turret"/><link name="upper"/><link name="fore"/><link name="hand"/>
  <joint name="yaw" type="revolute"><parent link="base"/><child link="turret"/><axis xyz="0 0 1"/>
    <limit lower="-3.14159" upper="3.14159" effort="1" velocity="1"/></joint>
  <joint name="shoulder" type="revolute"><parent link="turret"/><child link="upper"/><axis xyz="0 1 0"/>
    <limit lower="-3.14159" upper="3.14159" effort="1" velocity="1"/></joint>
  <joint name="elbow" type="revolute"><parent link="upper"/><child link="fore"/><origin xyz="0.5 0 0"/>
    <axis xyz="0 1 0"/><limit lower="-3.14159" upper="3.14159" effort="1" velocity="1"/></joint>
  <joint name="wrist" type="fixed"><parent link="fore"/><child link="hand"/><origin xyz="0.3 0 0"/></joint>
</robot>"""


def test_planar_2r_arm_reaches_an_annulus(tmp_path):
    path = tmp_path / "arm2r.urdf"
    path.write_text(ARM_2R.format(l1=0.4, l2=0.25))
    m = screwkin.load(path)
    res = workspace(m, "hand", point=True, method="grid", resolution=0.01)
    exact = np.pi * (0.65**2 - 0.15**2)
    assert res.dimension == 2
    assert res.volume == pytest.approx(exact, rel=5e-3)


def test_sampling_spherical_shell_of_an_elbow_arm(tmp_path):
    path = tmp_path / "elbow3r.urdf"
    path.write_text(ARM_3R)
    m = screwkin.load(path)
    res = workspace(m, "hand", point=True, resolution=0.05, samples=400_000)
    assert res.method == "sampling" and res.dimension == 3
    exact = 4 / 3 * np.pi * (0.8**3 - 0.2**3)
    # occupied cells of h = 5 cm: the cells cut by the two spheres count whole, so the count
    # exceeds the shell by up to (their area) x (the cell's half diagonal), and sparse cells may
    # be missed (measured 2.378 against 2.111)
    area = 4 * np.pi * (0.8**2 + 0.2**2)
    assert 0.97 * exact < res.volume < exact + area * 0.05 * np.sqrt(3) / 2
    r = np.linalg.norm(res.positions, axis=1)
    assert r.max() <= 0.8 + 0.05 and r.min() >= 0.2 - 0.05


# ------------------------------------------------------------------ batched rows, IK of a gear
@pytest.mark.parametrize("name", ["delta_parallelogram", "five_bar", "bennett", "planar_3rpr", "watt_sixbar",
                                  "gear_train_idler", "rack_pinion", "tsai_3upu"])
def test_batched_rows_match_closure_system(name):
    m = screwkin.load(ROBOTS / f"{name}.urdf")
    bc = BatchClosure(m, check=0)
    Q = np.array([pin.randomConfiguration(m.model, -np.ones(m.model.nq), np.ones(m.model.nq)) for _ in range(5)])
    r, K = bc.evaluate(Q)
    for q, rq, Kq in zip(Q, r, K, strict=True):  # ClosureSystem: the per-configuration rows every solver uses
        r_ref, K_ref = bc.system.evaluate(q, True, solver=True)
        assert np.allclose(rq, r_ref, atol=1e-10) and np.allclose(Kq, K_ref, atol=1e-10)


def test_inverse_kinematics_keeps_the_gear_mesh():
    # rack_pinion: pinion of pitch radius 0.04 m meshing with the rack: moving the rack by x
    # turns the pinion by -x / 0.04 (before, IK ignored the mesh and kept the file's pinion angle)
    m = screwkin.load(ROBOTS / "rack_pinion.urdf")
    fid = m.link_frame("rack")
    pin.framesForwardKinematics(m.model, m.data, pin.neutral(m.model))
    M = m.data.oMf[fid].copy()
    for dx in (0.01, -0.02, 0.035):
        target = pin.SE3(M.rotation, M.translation + np.array([dx, 0, 0]))
        res = inverse_kinematics(m, "rack", target)
        assert res.solutions
        for s in res.solutions:
            assert s.joints["rack_joint"] == pytest.approx(dx, abs=1e-9)
            assert s.joints["pinion_joint"] == pytest.approx(-dx / 0.04, abs=1e-7)
    out = screwkin_cli("ik", str(ROBOTS / "rack_pinion.urdf"), "--output", "rack", "--pose", "-0.14 0.04 0 0 0 0", "--json")
    assert out.returncode == 0, out.stderr
    joints = json.loads(out.stdout)["solutions"][0]["joints"]
    assert joints["pinion_joint"] == pytest.approx(-joints["rack_joint"] / 0.04, abs=1e-7)


# ------------------------------------------------------------------------------------------ CLI
def test_cli_json_png_csv(tmp_path):
    png, csv = tmp_path / "w.png", tmp_path / "w.csv"
    out = screwkin_cli("workspace", str(ROBOTS / "five_bar.urdf"), "--output", "tip", "--point", "--resolution", "1cm",
              "--json", "--png", str(png), "--csv", str(csv))
    assert out.returncode == 0, out.stderr
    d = json.loads(out.stdout)
    for key in ("volume", "free_volume", "conditioning_min", "conditioning_mean", "resolution", "points", "notes"):
        assert key in d
    assert d["resolution"] == pytest.approx(0.01)
    api = workspace(screwkin.load(ROBOTS / "five_bar.urdf"), "tip", point=True, resolution=0.01)
    assert d["volume"] == pytest.approx(api.volume, rel=1e-12)  # the CLI is a thin edge
    assert png.stat().st_size > 10_000
    rows = csv.read_text().splitlines()
    assert len(rows) == len(api.positions) + 1


@pytest.mark.parametrize("args, code, words", [
    (["--output", "nowhere"], 2, "nowhere"),
    (["--output", "tip", "--bounds", "0:1"], 2, "bounds"),
    (["--output", "tip", "--bounds", "a:b,c:d"], 2, "'a' is not a number"),
    (["--output", "tip", "--resolution", "-1"], 2, "resolution"),
    (["--output", "tip", "--method", "sampling"], 2, "serial"),
    (["--output", "tip", "--orientation", "0 0"], 2, "orientation"),
    (["--output", "tip", "--samples", "0"], 2, "samples"),
])
def test_cli_errors_are_one_line(args, code, words):
    out = screwkin_cli("workspace", str(ROBOTS / "five_bar.urdf"), *args)
    assert out.returncode == code, out.stderr
    errors = [line for line in out.stderr.strip().splitlines() if not line.startswith("note: ")]  # the mode: said
    assert len(errors) == 1 and "Traceback" not in out.stderr
    assert words and words in out.stderr


def test_one_dof_mechanism_is_told_to_sweep():
    out = screwkin_cli("workspace", str(ROBOTS / "fourbar_crank_rocker.urdf"), "--output", "coupler", "--point")
    assert out.returncode == 2 and "sweep" in out.stderr
