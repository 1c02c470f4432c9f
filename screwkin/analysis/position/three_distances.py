"""Every assembly mode of a planar platform on three distances (a 3-RPR and its kin), in closed form.

The mechanism (model.leg_chains' platform): one body, the platform, joined to the ground by three legs,
each a revolute at a ground point A_k, a slide -- the input --, and a revolute (in the tree) or a loop
joint at a platform point B_k; every revolute axis parallel to one normal n, so that the platform
moves in a plane (the leg that carries it in the tree is planar).  With the slides held, each leg is
the distance between A_k and B_k, and the forward kinematics is model.planar_distances': one
polynomial of degree at most six in t = tan(phi / 2) (phi: the platform's turn from its drawn pose),
built exactly, every root accounted for -- a pose (real or complex), or a root where the two linear
equations have no solution (spurious), or t = +-i.  Each real pose is carried onto the file's joints
(each leg's angles from its direction, model.leg_chains.leg_poses, the angle set within the limits and
nearest the reference), polished by undamped Newton on Pinocchio's closure (model.kernel.newton), and
checked: it closes, and the platform stayed where the closed form put it.  Where any of that fails, or
the polynomial vanishes identically (a continuum), the caller (analysis.position.certified) takes the
homotopy instead, with the reason.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from ...model.cuts import Assembly
from ...model.geometry import plane_basis
from ...model.kernel import newton
from ...model.leg_chains import Platform, best_set, common_output, leg_poses, platform_of, set_leg
from ...model.planar_distances import PlanarRoots, planar_poses
from ...model.state import KinematicState
from ...model.subproblems import rotation

__all__ = ["PlanarPlatform", "ThreeDistanceModes", "planar_platform", "pose_onto_joints", "three_distance_modes"]


@dataclass(frozen=True)
class PlanarPlatform:
    """A platform on three distances in a plane: the leg_chains Platform, the plane's basis (e1, e2, n),
    the ground points ``a`` and the platform points at the drawn pose ``b`` (3, 2) in (e1, e2), each
    leg's slide (q index), its vector from A to its end at slide 0 (d0) and its slide's axis (u0), and
    the platform point's height above A along n (the leg's must match it)."""

    platform: Platform
    basis: tuple
    a: np.ndarray
    b: np.ndarray
    slides: tuple
    d0: np.ndarray
    u0: np.ndarray
    heights: np.ndarray

    def quadratics(self) -> np.ndarray:
        """(3, 3): leg k's squared length in the plane, |v|^2 - (v . n)^2 with v = d0 + s u0, is
        Q[k, 0] s^2 + Q[k, 1] s + Q[k, 2] at its slide s."""
        d0, u0, n = self.d0, self.u0, self.basis[2]
        dn, un = d0 @ n, u0 @ n
        return np.stack([np.sum(u0 * u0, axis=1) - un ** 2, 2 * (np.sum(d0 * u0, axis=1) - dn * un),
                         np.sum(d0 * d0, axis=1) - dn ** 2], axis=1)

    def length2(self, s: np.ndarray) -> np.ndarray:
        """The three legs' squared lengths in the plane at their slides s (3,)."""
        Q = self.quadratics()
        return Q[:, 0] * s * s + Q[:, 1] * s + Q[:, 2]


@dataclass(frozen=True)
class ThreeDistanceModes:
    """The real modes [(q, model.cuts.Assembly, roots that reach it, simple)] -- simple None for a simple
    root, False for a multiple one -- and how every root of the polynomial was accounted for (``roots``,
    model.planar_distances.PlanarRoots), the real roots' t = tan(phi / 2), ``seconds``."""

    modes: list
    roots: PlanarRoots
    t_real: tuple
    seconds: float


def planar_platform(solver) -> PlanarPlatform | None:
    """The planar platform on three distances of ``solver``'s mechanism with its inputs (the three slides,
    nothing else held), or None when it is no such mechanism (see the module).  Read once per inputs."""
    mech = solver.mech
    key = ("three distances", tuple(int(v) for v in solver.frozen))
    if key not in mech.cache:
        mech.cache[key] = _recognized(solver)
    return mech.cache[key]


def _recognized(solver) -> PlanarPlatform | None:
    mech, tol = solver.mech, solver.mech.tolerances
    if not mech.cuts or mech.closure.row_inputs:
        return None
    out = common_output(mech)
    platform = platform_of(mech, out) if out else None
    if platform is None or platform.free is not None or len(platform.legs) != 3:
        return None
    model = mech.model
    if sorted(int(v) for v in solver.frozen) != sorted(model.joints[leg.slide].idx_v for leg in platform.legs):
        return None  # the inputs are not the three slides
    carrier = next((leg for leg in platform.legs if leg.cut is None), None)
    if carrier is None or len(carrier.a_axes) != 1:
        return None
    n = np.asarray(carrier.a_axes[0], float)
    n = n / np.linalg.norm(n)

    def parallel(w) -> bool:
        w = np.asarray(w, float)
        return bool(np.linalg.norm(np.cross(w / np.linalg.norm(w), n)) <= tol.closed_form)

    state = KinematicState(mech, pin.neutral(model))
    cuts = {c.name: c for c in mech.cuts}
    for leg in platform.legs:
        if len(leg.a_axes) != 1 or len(leg.b_axes) > 1 or not all(parallel(w) for w in leg.a_axes + leg.b_axes):
            return None
        if leg.cut is not None:
            c = cuts[leg.cut]
            if c.type == "spherical":
                continue
            if c.type not in ("revolute", "continuous"):
                return None
            if not parallel(state.frame_placement(c.frame1).rotation @ np.asarray(c.axis, float)):
                return None
    e1, e2, n = plane_basis(n)
    M0 = platform.M0
    A = np.array([leg.A for leg in platform.legs], float)
    B = np.array([leg.f0 if leg.cut is None else M0.act(np.asarray(leg.b_local, float)) for leg in platform.legs])
    d0 = np.array([np.asarray(leg.f0) - np.asarray(leg.A) for leg in platform.legs], float)
    plane = np.stack([e1, e2])
    return PlanarPlatform(platform, (e1, e2, n), A @ plane.T, B @ plane.T,
                          tuple(model.joints[leg.slide].idx_q for leg in platform.legs), d0,
                          np.array([leg.u0 for leg in platform.legs], float), (B - A) @ n)


def three_distance_modes(solver, values: dict) -> ThreeDistanceModes | str | None:
    """Every assembly mode at the input ``values`` (see the module); None where the mechanism is no planar
    platform on three distances, a sentence where it is one but the closed form does not settle it."""
    t0 = time.perf_counter()
    pp = planar_platform(solver)
    if pp is None:
        return None
    mech, tol = solver.mech, solver.mech.tolerances
    L = max(mech.length, 1e-3)
    ref = solver.reference()
    q_in = solver.set_inputs(mech.neutral() if ref is None else ref, values)
    x = np.array([q_in[i] for i in pp.slides])
    v = pp.d0 + x[:, None] * pp.u0  # each leg from A to its end, before its revolutes turn
    n = pp.basis[2]
    rise = v @ n
    if np.abs(rise - pp.heights).max() > tol.closed_check * L:
        return "a leg's end and its platform point are not at one height along the plane's normal"
    roots = planar_poses(pp.a, pp.b, pp.length2(x), tol)
    if isinstance(roots, str):
        return roots
    if roots.unexplained:
        return "a root of the polynomial in tan(phi/2) is not accounted for: " + "; ".join(roots.unexplained)
    if roots.accounted != roots.degree:
        return f"{roots.accounted} of the {roots.degree} roots of the polynomial in tan(phi/2) accounted for"
    lone = _lone(roots, tol.unit_circle)
    if lone:
        return f"{lone} complex pose(s) of the polynomial in tan(phi/2) without their conjugate"
    found = []  # [signature, q, Assembly, roots, simple]
    for pose in roots.real:
        got = pose_onto_joints(solver, pp, q_in, x, float(pose.phi.real), pose.u.real, ref)
        if isinstance(got, str):
            return got
        q, a = got
        sig = solver.signature(q)
        same = next((m for m in found if solver.same_mode(m[0], sig)), None)
        if same is not None:  # two poses of the polynomial, one placement: a multiple root
            same[3] += pose.roots
            same[4] = False
            continue
        found.append([sig, q, a, pose.roots, None if pose.roots == 1 else False])
    t_real = tuple(float(np.tan(p.phi.real / 2)) for p in roots.real)
    return ThreeDistanceModes([(q, a, k, simple) for _, q, a, k, simple in found], roots, t_real,
                              time.perf_counter() - t0)


def _lone(roots: PlanarRoots, tol: float) -> int:
    """Complex poses whose conjugate (within ``tol``, relative) is not among the others."""
    cplx = roots.complex
    return sum(not any(k != i and abs(np.conj(p.phi) - o.phi) <= tol * (1 + abs(p.phi)) for k, o in enumerate(cplx))
               for i, p in enumerate(cplx))


def pose_onto_joints(solver, pp: PlanarPlatform, q_in: np.ndarray, x: np.ndarray, phi: float,
                 u: np.ndarray, ref: np.ndarray | None) -> tuple | str:
    """(q, Assembly) of the real pose (phi, u = B_1 - A_1 in the plane) on the file's joints, polished, or
    why not."""
    mech, tol, model = solver.mech, solver.mech.tolerances, solver.mech.model
    L = max(mech.length, 1e-3)
    e1, e2, n = pp.basis
    c, s = np.cos(phi), np.sin(phi)
    shift = pp.a[0] + u - np.array([c * pp.b[0, 0] - s * pp.b[0, 1], s * pp.b[0, 0] + c * pp.b[0, 1]])
    g = pin.SE3(rotation(n, phi), shift[0] * e1 + shift[1] * e2)  # the platform's motion from its drawn pose
    P = g * pp.platform.M0
    q = np.array(q_in, float)
    for k, leg in enumerate(pp.platform.legs):
        poses, why, _ = leg_poses(pp.platform, leg, P)
        pose = min(poses, key=lambda p: abs(p.x - x[k])) if poses else None
        if pose is None or abs(pose.x - x[k]) > tol.geometry * L:
            return f"the closed form's pose at phi = {np.degrees(phi):.6g} deg does not lift onto leg {leg.name}" \
                   + (f" ({why})" if why else "")
        set_leg(model, q, pose, best_set(mech, q, pose, near=ref))
        q[pp.slides[k]] = x[k]  # the input as given
    a = newton.polish(mech.closure.pinocchio, q, solver.frozen)
    if not a.residual <= tol.closure:
        return (f"the closed form's pose at phi = {np.degrees(phi):.6g} deg does not close the loops (residual "
                f"{a.residual:.2g})")
    moved = KinematicState(mech, a.q).joint_placement(pp.platform.out_joint)
    if np.abs(moved.translation - P.translation).max() > tol.geometry * L or \
            np.abs(moved.rotation - P.rotation).max() > tol.geometry:
        return f"the closed form's pose at phi = {np.degrees(phi):.6g} deg moved when polished"
    q = solver._wrap(a.q)
    return q, Assembly(q, a.residual, a.iterations, "the three distances' closed form")
