"""Dynamics at constant input speed, each against something outside the code: a four-bar's input
torque by the energy method from closed-form kinematics (law of cosines), the power balance of a
slider-crank from finite differences of its links' placements, statics at zero speed, Newton's
law for the shaking force, and the errors a user meets."""

import json

import numpy as np
import pinocchio as pin
import pytest

import screwkin
from conftest import DATA, ROBOTS
from screwkin.analysis.forces.dynamics import Load, dynamics
from screwkin.analysis.forces.statics import statics
from screwkin.cli import main

FOURBAR = DATA / "fourbar_inertial.urdf"
A, B, C, D = 0.04, 0.12, 0.08, 0.10  # crank, coupler, rocker, ground [m]
MASS = {"crank": 0.3, "coupler": 0.5, "rocker": 0.4}
G = 9.81


def fourbar_closed_form(t2, sigma):
    """Joint centres and bar angles of the four-bar at crank angle t2 (law of cosines: B at distance
    b from A and c from D, on the side sigma of AD), and the bars' angular rates per unit crank rate
    from the derivative of the vector loop a e2 + b e3 - c e4 - d = 0 (a 2 x 2 linear system)."""
    pA = A * np.array([np.cos(t2), np.sin(t2)])
    pD = np.array([D, 0.0])
    f = np.linalg.norm(pD - pA)
    along = (B * B - C * C + f * f) / (2 * f)
    u = (pD - pA) / f
    pB = pA + along * u + sigma * np.sqrt(B * B - along * along) * np.array([-u[1], u[0]])
    t3 = np.arctan2(*(pB - pA)[::-1])
    t4 = np.arctan2(*(pB - pD)[::-1])
    M = np.array([[-B * np.sin(t3), C * np.sin(t4)], [B * np.cos(t3), -C * np.cos(t4)]])
    w3, w4 = np.linalg.solve(M, [A * np.sin(t2), -A * np.cos(t2)])
    return pA, pB, pD, t3, t4, w3, w4


def side(pB):
    """+1 when B lies to the left of the line from A (at the crank angle 0) to D, else -1."""
    u, w = np.array([D - A, 0.0]), pB - np.array([A, 0.0])
    return float(np.sign(u[0] * w[1] - u[1] * w[0]))


def fourbar_energies(t2, sigma, omega):
    """T and V (gravity -g along y) of the uniform bars: T = sum 1/2 (m v_c^2 + m L^2/12 w^2)."""
    pA, pB, pD, t3, t4, w3, w4 = fourbar_closed_form(t2, sigma)
    perp = np.array([-np.sin(t2), np.cos(t2)])
    vA = A * omega * perp
    vB = C * omega * w4 * np.array([-np.sin(t4), np.cos(t4)])
    bars = [("crank", A, pA / 2, vA / 2, omega), ("coupler", B, (pA + pB) / 2, (vA + vB) / 2, omega * w3),
            ("rocker", C, (pD + pB) / 2, vB / 2, omega * w4)]
    T = sum(0.5 * MASS[n] * (v @ v + L * L / 12 * w * w) for n, L, _, v, w in bars)
    V = sum(MASS[n] * G * c[1] for n, _, c, _, _ in bars)
    return T, V


def test_fourbar_input_torque_by_the_energy_method():
    """tau omega = dT/dt + dV/dt at constant omega: tau = dT/dtheta + dV/dtheta, both by central
    differences of the closed-form energies (h = 1e-5 rad), to 1e-6 of the largest torque."""
    mech = screwkin.load(FOURBAR)
    omega = 2 * np.pi * 100 / 60
    r = dynamics(mech, "crank_joint", omega, 0.0, 2 * np.pi, 36, gravity=(0, -G, 0))
    assert r.completed and r.effort_units == {"crank_joint": "N m"}
    # the assembly mode screwkin follows: the side of AD the point B lies on at the start
    pin.framesForwardKinematics(mech.model, mech.data, r.q[0])
    pB = mech.data.oMf[mech.link_frame("rocker")].act(np.array([C, 0, 0]))[:2]
    sigma = side(pB)
    h = 1e-5
    expected = []
    for t2 in r.values:
        (Tp, Vp), (Tm, Vm) = fourbar_energies(t2 + h, sigma, omega), fourbar_energies(t2 - h, sigma, omega)
        expected.append((Tp - Tm + Vp - Vm) / (2 * h))
        assert fourbar_energies(t2, sigma, omega)[0] == pytest.approx(r.kinetic_energy[len(expected) - 1], rel=1e-7)
    expected = np.array(expected)
    tau = r.efforts["crank_joint"]
    np.testing.assert_allclose(tau, expected, rtol=0, atol=1e-6 * np.abs(expected).max())
    assert r.peak["crank_joint"] == pytest.approx(np.abs(expected).max(), rel=1e-6)
    rms = np.sqrt(np.trapezoid(expected**2, r.values) / (2 * np.pi))
    assert r.rms["crank_joint"] == pytest.approx(rms, rel=1e-6)
    # over a whole turn the input's work is the change of T + V: none (trapezoid error on 10 deg steps)
    assert abs(r.mean["crank_joint"]) < 1e-2 * np.abs(expected).max()
    # the planar loop's out-of-plane rows are redundant: named, and the in-plane reactions are determined
    assert r.indeterminate == 3
    assert set(r.open_components["B"]) == {"fz", "mx", "my"}
    # flywheel: the energy fluctuation is max - min of the integral of (tau - mean): from T + V
    # (the work of the input is T + V up to a constant), the mean torque is zero over a turn
    assert r.flywheel.energy_fluctuation is not None
    E = np.array([sum(fourbar_energies(t, sigma, omega)) for t in r.values])
    assert r.flywheel.energy_fluctuation == pytest.approx(E.max() - E.min(), rel=2e-2)  # trapezoid on 10 deg steps


def test_shaking_force_is_newtons_law():
    """What the moving links exert on the ground is minus the rate of change of their momentum
    plus their weights: -sum m_i a_ci + sum m_i g, the accelerations of the centres of mass taken
    from the closed form by central differences."""
    mech = screwkin.load(FOURBAR)
    omega = 5.0
    r = dynamics(mech, "crank_joint", omega, 0.3, 1.3, 4, gravity=(0, -G, 0))
    pin.framesForwardKinematics(mech.model, mech.data, r.q[0])
    pB = mech.data.oMf[mech.link_frame("rocker")].act(np.array([C, 0, 0]))[:2]
    sigma = side(pB)

    def momentum_centres(t2):
        pA, pB, pD, *_ = fourbar_closed_form(t2, sigma)
        return MASS["crank"] * pA / 2 + MASS["coupler"] * (pA + pB) / 2 + MASS["rocker"] * (pD + pB) / 2

    h = 1e-4
    total = sum(MASS.values())
    for t2, force in zip(r.values, r.shaking_force):
        acc = (momentum_centres(t2 + h) - 2 * momentum_centres(t2) + momentum_centres(t2 - h)) / h**2 * omega**2
        expected = -acc + total * np.array([0, -G])
        np.testing.assert_allclose(force[:2], expected, rtol=0, atol=1e-5 * np.abs(expected).max())


def _stencil(y, h):
    """First derivative of a periodic sequence by the five-point central stencil (error h^4)."""
    return (np.roll(y, 2) - 8 * np.roll(y, 1) + 8 * np.roll(y, -1) - np.roll(y, -2)) / (12 * h)


def test_slider_crank_power_balance_at_every_step():
    """Input power = dT/dt + dV/dt - power of the load, at every step of a turn: T and V from the
    links' placements (Pinocchio's forward kinematics at each step), their velocities and rates by
    five-point differences along the motion (the input turns at constant speed)."""
    mech = screwkin.load(ROBOTS / "slider_crank_offset.urdf")
    omega, n = 2 * np.pi * 120 / 60, 180
    F = np.array([-20.0, 5.0, 0.0])
    g = np.array([0.0, -G, 0.0])
    r = dynamics(mech, "crank_joint", omega, 0.0, 2 * np.pi, n, gravity=tuple(g),
                 loads=(Load("slider", (*F, 0.0, 0.0, 0.0)),))
    assert r.completed and r.indeterminate == 3
    model, data = mech.model, mech.data
    links = ["crank", "rod", "slider"]
    centres = {k: [] for k in links}
    angles = {k: [] for k in links}
    slider = []
    for q in r.q[:-1]:  # the last configuration is the first one again
        pin.framesForwardKinematics(model, data, q)
        for k in links:
            M = data.oMf[mech.link_frame(k)]
            I = model.inertias[model.frames[mech.link_frame(k)].parentJoint]
            centres[k].append(M.act(I.lever))
            angles[k].append(np.arctan2(M.rotation[1, 0], M.rotation[0, 0]))
        slider.append(data.oMf[mech.link_frame("slider")].translation.copy())
    dt = 2 * np.pi / n / omega
    T = np.zeros(n)
    V = np.zeros(n)
    for k in links:
        I = model.inertias[model.frames[mech.link_frame(k)].parentJoint]
        v = np.stack([_stencil(np.array(centres[k])[:, i], dt) for i in range(3)], axis=1)
        c, s_ = np.cos(angles[k]), np.sin(angles[k])  # w = c s' - s c' (the angle itself jumps by a turn)
        w = c * _stencil(s_, dt) - s_ * _stencil(c, dt)
        T += 0.5 * (I.mass * np.sum(v * v, axis=1) + I.inertia[2, 2] * w * w)
        V -= I.mass * np.array(centres[k]) @ g
    v_slider = np.stack([_stencil(np.array(slider)[:, i], dt) for i in range(3)], axis=1)
    expected = _stencil(T, dt) + _stencil(V, dt) - v_slider @ F
    power = r.input_power[:-1]
    np.testing.assert_allclose(power, expected, rtol=0, atol=1e-6 * np.abs(expected).max())
    np.testing.assert_allclose(power, r.efforts["crank_joint"][:-1] * omega, rtol=1e-12)
    np.testing.assert_allclose(r.load_power[:-1], v_slider @ F, rtol=0, atol=1e-6 * np.abs(v_slider @ F).max())


def test_statics_equals_dynamics_at_zero_speed():
    """At zero speed the efforts and the determined reactions are those of statics (virtual work)
    for the same weights and load."""
    mech = screwkin.load(FOURBAR)
    g = (0.0, -G, 0.0)
    w = (3.0, -2.0, 0.0, 0.0, 0.0, 0.25)
    r = dynamics(mech, "crank_joint", 0.0, 0.0, 2 * np.pi, 8, gravity=g, loads=(Load("rocker", w),))
    assert np.all(r.kinetic_energy == 0)
    saved = pin.Motion(mech.model.gravity)
    mech.model.gravity = pin.Motion(np.array(g), np.zeros(3))
    try:
        for k, q in enumerate(r.q):
            s = statics(mech, q, output="rocker", wrench=w, gravity=True)
            assert r.efforts["crank_joint"][k] == pytest.approx(s.efforts["crank_joint"], rel=1e-9, abs=1e-12)
            for x in s.reactions:
                for c, value in enumerate(x.wrench):
                    if value is not None:
                        assert r.reactions[x.joint][k, c] == pytest.approx(value, rel=1e-9, abs=1e-9)
    finally:
        mech.model.gravity = saved


def test_cli_json_contract_and_outputs(tmp_path, capsys):
    csv, png = tmp_path / "d.csv", tmp_path / "d.png"
    code = main(["dynamics", str(FOURBAR), "--input", "crank_joint", "--speed", "60rpm", "--from", "0deg",
                 "--to", "360deg", "--steps", "12", "--gravity", "0,-9.81,0", "--point", "P=coupler:60mm,0,0",
                 "--load", "P:1N,0,0,0,0,0", "--json", "--csv", str(csv), "--plot", str(png)])
    assert code == 0
    d = json.loads(capsys.readouterr().out)
    for key in ("values", "efforts", "reactions", "shaking", "kinetic_energy", "units"):
        assert key in d
    assert len(d["values"]) == 13 and d["values"][-1] == pytest.approx(2 * np.pi)
    assert set(d["shaking"]) >= {"force", "moment"} and len(d["shaking"]["force"][0]) == 3
    assert len(d["reactions"]["B"][0]) == 6 and len(d["efforts"]["crank_joint"]) == 13
    assert d["units"]["efforts"] == {"crank_joint": "N m"} and d["speed"] == pytest.approx(2 * np.pi)
    assert d["loads"][0]["link"] == "coupler" and d["loads"][0]["point"] == pytest.approx([0.06, 0, 0])
    assert csv.read_text().splitlines()[0].startswith("crank_joint [deg],crank_joint [N*m]")
    pytest.importorskip("matplotlib")
    assert png.stat().st_size > 1000


def test_cli_text(capsys):
    assert main(["dynamics", str(FOURBAR), "--input", "crank_joint", "--speed", "2rad/s", "--steps", "6"]) == 0
    out = capsys.readouterr().out
    assert "crank_joint [deg]" in out and "crank_joint [N*m]" in out  # default range: a turn, in degrees
    assert "peak |effort|" in out and "RMS" in out and "kg*m^2" in out
    assert "gravity: none" in out


def test_missing_inertial_is_a_file_error_naming_the_link(tmp_path, capsys):
    text = FOURBAR.read_text()
    start = text.index('<inertial>', text.index('<link name="rocker">'))
    bad = tmp_path / "no_inertial.urdf"
    bad.write_text(text[:start] + text[text.index("</inertial>", start) + len("</inertial>"):])
    code = main(["dynamics", str(bad), "--input", "crank_joint", "--speed", "60rpm"])
    err = capsys.readouterr().err
    assert code == 1 and "'rocker'" in err and "<inertial>" in err and len(err.strip().splitlines()) == 1


@pytest.mark.parametrize("speed", ["30mm", "10N", "fast"])
def test_bad_speed_is_a_usage_error(speed, capsys):
    code = main(["dynamics", str(FOURBAR), "--input", "crank_joint", "--speed", speed])
    err = capsys.readouterr().err
    assert code == 2 and "speed" in err.lower() or "unit" in err.lower() or "number" in err.lower()
    assert code == 2 and len(err.strip().splitlines()) == 1


@pytest.mark.parametrize("args", [["--cs", "0"], ["--gravity", "0,0"], ["--load", "rocker:1,2,3"],
                                  ["--load", "nowhere:1,0,0,0,0,0"], ["--steps", "0"]])
def test_bad_options_are_usage_errors(args, capsys):
    code = main(["dynamics", str(FOURBAR), "--input", "crank_joint", "--speed", "60rpm", *args])
    err = capsys.readouterr().err
    assert code == 2 and len(err.strip().splitlines()) == 1


def _mjcf_fourbar():
    """The four-bar of fourbar_inertial.urdf written as MuJoCo writes a loop: a tree of bodies with
    hinges, and an <equality><connect> between a site on the coupler's end and one on the rocker's."""
    def inertial(name, L):
        m = MASS[name]
        return f'<inertial pos="{L / 2!r} 0 0" mass="{m!r}" diaginertia="1e-6 {m * L * L / 12!r} {m * L * L / 12!r}"/>'

    return f'''<mujoco><option gravity="0 {-G!r} 0" jacobian="dense"/>
      <worldbody>
        <body name="crank">{inertial("crank", A)}<joint name="crank_joint" type="hinge" axis="0 0 1"/>
          <body name="coupler" pos="{A!r} 0 0">{inertial("coupler", B)}
            <joint name="coupler_joint" type="hinge" axis="0 0 1"/><site name="B1" pos="{B!r} 0 0"/></body></body>
        <body name="rocker" pos="{D!r} 0 0">{inertial("rocker", C)}
          <joint name="rocker_joint" type="hinge" axis="0 0 1"/><site name="B2" pos="{C!r} 0 0"/></body>
      </worldbody>
      <equality><connect site1="B1" site2="B2"/></equality></mujoco>'''


def test_mujoco_needs_the_input_torque_screwkin_predicts():
    """MuJoCo as the oracle: at each of screwkin's (q, q', q''), MuJoCo's inverse dynamics of the tree
    (mj_inverse, equality constraints off) projected onto the motions its connect constraint allows
    (the null space of its constraint Jacobian efc_J) is the input torque; that Jacobian has the rank
    screwkin reports, and MuJoCo sees the loop closed."""
    mujoco = pytest.importorskip("mujoco")
    model = mujoco.MjModel.from_xml_string(_mjcf_fourbar())
    data = mujoco.MjData(model)
    mech = screwkin.load(FOURBAR)
    r = dynamics(mech, "crank_joint", 2 * np.pi * 90 / 60, 0.0, 2 * np.pi, 24, gravity=(0, -G, 0))
    names = ["crank_joint", "coupler_joint", "rocker_joint"]
    sv = [mech.coordinate(n).idx_v for n in names]
    sq = [mech.coordinate(n).idx_q for n in names]
    mv = [int(model.jnt_dofadr[model.joint(n).id]) for n in names]
    mq = [int(model.jnt_qposadr[model.joint(n).id]) for n in names]
    rank = mech.mobility().rank
    for k in range(len(r.values)):
        data.qpos[mq], data.qvel[mv] = r.q[k][sq], r.rates[k][sv]
        model.opt.disableflags = 0
        mujoco.mj_forward(model, data)
        J = data.efc_J.reshape(data.nefc, model.nv).copy()
        assert np.abs(data.efc_pos).max() < 1e-9  # the loop closed where screwkin closed it
        s = np.linalg.svd(J, compute_uv=False)
        assert int(np.sum(s > 1e-9 * s[0])) == rank == 2
        model.opt.disableflags = int(mujoco.mjtDisableBit.mjDSBL_EQUALITY)
        data.qacc[mv] = r.accelerations[k][sv]
        mujoco.mj_inverse(model, data)
        N = np.linalg.svd(J)[2][rank:].T  # the joint rates the connect allows
        tau = float(N[:, 0] @ data.qfrc_inverse / N[mv[0], 0])
        assert r.efforts["crank_joint"][k] == pytest.approx(tau, rel=1e-8, abs=1e-10)
    model.opt.disableflags = 0


@pytest.mark.parametrize("range_, shown", [((), "deg"), (("--from", "0", "--to", "1"), "rad"),
                                           (("--from", "0", "--to", "1turn"), "turn")])
def test_the_input_is_shown_in_the_unit_typed(range_, shown, capsys):
    assert main(["dynamics", str(FOURBAR), "--input", "crank_joint", "--speed", "1", "--steps", "2", *range_]) == 0
    assert f"crank_joint [{shown}]" in capsys.readouterr().out


@pytest.mark.parametrize("name, load_on", [("bennett", "link3"), ("quick_return_slot", "slotted")])
def test_shaking_wrench_is_the_momentum_balance(name, load_on):
    """The wrench on the ground (force, moment about the world origin) is the moving bodies' weights
    and the load less the rate of change of their momentum, each body's Newton-Euler
    I a + v x* I v from Pinocchio's forward kinematics at the same (q, q', q''): on a spatial
    overconstrained loop with a cut joint at the ground (Bennett) and a planar slot."""
    mech = screwkin.load(ROBOTS / f"{name}.urdf")
    g = np.array([0.3, -G, -2.0])
    w = np.array([1.0, 2.0, -3.0, 0.1, 0.2, 0.3])
    r = dynamics(mech, mech.actuated[0], 3.0, 0.1, 1.1, 4, gravity=tuple(g), loads=(Load(load_on, tuple(w)),))
    model, data = mech.model, mech.data
    for k in range(len(r.values)):
        pin.forwardKinematics(model, data, r.q[k], r.rates[k], r.accelerations[k])
        pin.updateFramePlacements(model, data)
        o = data.oMf[mech.link_frame(load_on)].translation
        force, moment = w[:3].copy(), w[3:] + np.cross(o, w[:3])
        for i in range(1, model.njoints):
            inertia, M = model.inertias[i], data.oMi[i]
            c = M.act(inertia.lever)
            dh = M.act(inertia * data.a[i] + data.v[i].cross(inertia * data.v[i]))
            force += inertia.mass * g - dh.linear
            moment += np.cross(c, inertia.mass * g) - dh.angular
        np.testing.assert_allclose(r.shaking_force[k], force, rtol=0, atol=1e-9 * np.abs(force).max())
        np.testing.assert_allclose(r.shaking_moment[k], moment, rtol=0, atol=1e-9 * np.abs(force).max())


def test_sdf_is_refused_since_its_inertias_are_not_read(capsys):
    code = main(["dynamics", str(DATA / "fourbar.sdf"), "--input", "A", "--speed", "1"])
    err = capsys.readouterr().err
    assert code == 1 and "SDF" in err and len(err.strip().splitlines()) == 1
