"""Every assembly mode of a Stewart-Gough platform by a coefficient-parameter homotopy from a generic
solution set kept per architecture (Morgan and Sommese 1989; Sommese and Wampler 2005, ch. 7).

The homotopy itself -- the platform as six distances, its generic solution set (solved once by
monodromy, kept in the cache folder), each query one straight segment from it, the endpoints sorted --
is model.homotopy.parameter's.  Here the real poses are carried back to the file's joints (the
carrying leg's angles by Paden-Kahan subproblems, the other legs by model.legs' lift) and polished on
Pinocchio's closure, and the certificate is checked before it is given: the generic set was complete,
no path failed, every real pose lifted and polished, the poses are distinct (q and -q are one), the
complex ones come in conjugate pairs, their number is at most 40 and each is a simple root; otherwise
the result says which check failed and is not called certified.
"""

from __future__ import annotations

import time

import numpy as np
import pinocchio as pin

from ...model.kernel import newton
from ...model.cuts import Assembly
from ...model.distances import chain_angles
from ...model.homotopy.parameter import BOUND, Architecture, generic_set, to_query
from ...model.state import KinematicState
from ...tolerances import Tolerances
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism

__all__ = ["platform_modes"]

#: A polished real pose that moved by more than this (relative to L) from its endpoint is another pose.
_MOVED = 1e-6


def platform_modes(solver, problem, closure, arch: Architecture, seed: int, tol: Tolerances, lift_legs) -> tuple:
    """The modes of a platform (see the module): (modes [(q, Assembly, angle sets, simple)], found, real,
    complex, certificate or None, reason, detail, check) -- analysis.position.certified makes them a
    Certified.  ``lift_legs(x)``: the configuration with the eliminated legs' angles solved from the
    closure's unknowns x, or None."""
    t0 = time.perf_counter()
    rng = np.random.default_rng(seed)
    roots, how, path, reused = generic_set(arch, rng, tol)
    t1 = time.perf_counter()
    query = to_query(arch, roots, tol, rng)
    ends, real, distinct, meets, lone = query.ends, query.real, query.distinct, query.meets, query.lone
    X, status = ends.X, ends.status
    closes = query.closes
    modes, lost = [], 0
    for i in distinct:
        if not real[i]:
            continue
        got = _onto_joints(solver, problem, closure, arch, X[i].real, lift_legs)
        if got is None:
            lost += 1
            continue
        q, a = got
        simple = status[i] == "regular" and not meets[i]
        modes.append((q, a, None, None if simple else False))
    n_real = len(modes) + lost
    n_complex = len(distinct) - n_real
    failed = int(np.sum(status == "failed"))
    singular = int(np.sum(closes & (status == "singular")))
    check = {"method": "coefficient-parameter homotopy", "generic_set": len(roots.X),
             "generic_set_certified_by": how, "paths": len(roots.X), "failed_paths": failed,
             "at_infinity": int(np.sum(status == "infinity")), "singular_endpoints": singular,
             "paths_meeting": int(meets.sum()), "bound": BOUND, "distinct_poses": len(distinct),
             "real_not_polished": lost, "complex_without_conjugate": int(lone),
             "counts": "platform poses (q and -q one pose)"}
    why = []
    if how is None:
        why.append(f"the generic solution set is not known to be complete ({roots.why or 'monodromy found ' + str(len(roots.X))})")
    if failed:
        why.append(f"{failed} of {len(roots.X)} paths failed")
    if lost:
        why.append(f"{lost} real pose(s) did not lift onto the file's joints")
    if lone:
        why.append(f"{lone} complex pose(s) without their conjugate")
    if len(distinct) > BOUND:
        why.append(f"{len(distinct)} distinct poses, more than the bound of {BOUND}")
    if singular or meets.any():
        why.append(f"{singular + int(meets.sum())} endpoint(s) singular or shared by several paths (a multiple pose)")
    check["checked"] = not why
    certificate = None
    if not why:
        certificate = (f"{len(distinct)} poses, a parameter homotopy from this architecture's generic solution set "
                       f"({len(roots.X)} poses, complete by {how}): {len(roots.X)} paths, none failed, "
                       f"{len(distinct)} distinct simple poses, at most {BOUND}")
    detail = {"roots": len(roots.X), "paths": int(roots.paths + ends.paths), "failed": int(roots.failed + failed),
              "at_infinity": check["at_infinity"], "generic_set": str(path) if path else None,
              "generic_set_reused": reused, "generic_seconds": round(t1 - t0, 3),
              "seconds": round(time.perf_counter() - t0, 3), "lost_polishing": lost}
    return modes, len(distinct), len(modes), n_complex, certificate, "; ".join(why), detail, check


def _onto_joints(solver, problem, closure, arch: Architecture, x: np.ndarray, lift_legs) -> tuple | None:
    """(q, Assembly) of the real pose x = (t / L, q) on the file's joints -- of its angle sets the one
    within the joint limits nearest the reference configuration -- or None."""
    model, L = problem.model, arch.L
    R = _wxyz(x[3:7]).toRotationMatrix()
    t = x[:3] * L
    candidates = []
    if arch.carrier is None:
        M = model.jointPlacements[arch.joint].inverse() * pin.SE3(R, t)
        q = np.array(problem.q_in, float)
        jm = model.joints[arch.joint]
        q[jm.idx_q:jm.idx_q + 7] = pin.SE3ToXYZQUAT(M)
        candidates.append(q)
    else:
        candidates = _carried(solver.mech, problem, arch, R, t)
    # the carrier's angle sets ranked as reported (within the limits, then nearest the reference); the
    # other legs' angles do not depend on which: the first that lifts and polishes is the one
    names = {model.names[j] for j in (arch.carrier[0] + arch.carrier[1] if arch.carrier else ())}
    ref = problem.ref

    def rank(q: np.ndarray) -> tuple:
        outside = any(n in names for n in solver.outside(solver._wrap(q)))
        dist = float(np.linalg.norm(solver.mech.difference(ref, q))) if ref is not None else 0.0
        return (outside, dist)

    for q in sorted(candidates, key=rank):
        full = lift_legs(closure.from_q(q))
        if full is None:
            continue
        a = newton.polish(problem.system.pinocchio, full, problem.frozen)
        if a.residual > solver.mech.tolerances.closure or not _same_pose(solver.mech, a.q, arch, R, t):
            continue
        q = solver._wrap(a.q)
        return q, Assembly(q, a.residual, a.iterations, "a homotopy's endpoint")
    return None


def _wxyz(q: np.ndarray):
    """pin.Quaternion's constructor order (w, x, y, z) from Pinocchio's coefficient order (x, y, z, w)."""
    q = np.asarray(q, float) / np.linalg.norm(q)
    return pin.Quaternion(q[3], q[0], q[1], q[2])


def _same_pose(mech: Mechanism, q: np.ndarray, arch: Architecture, R: np.ndarray, t: np.ndarray) -> bool:
    M = KinematicState(mech, q).joint_placement(arch.joint)
    return (np.abs(M.translation - t).max() <= _MOVED * arch.L and np.abs(M.rotation - R).max() <= _MOVED)


def _carried(mech: Mechanism, problem, arch: Architecture, R: np.ndarray, t: np.ndarray) -> list:
    """Configurations with the carrying leg's angles putting the platform's joint frame at (R, t)."""
    model = problem.model
    head, tail = arch.carrier
    q0 = np.array(problem.q_in, float)
    for j in head + tail:
        _set_angle(model, q0, j, 0.0)
    state = KinematicState(mech, q0)
    axes = {}
    for j in head + tail:
        w = state.joint_twists(j)[3:, 0]
        axes[j] = w / np.linalg.norm(w)
    M0 = state.joint_placement(arch.joint)
    p0 = M0.act(arch.B[0])
    p = R @ arch.B[0] + t
    out = []
    for th, ts in chain_angles([axes[j] for j in head], [axes[j] for j in tail], arch.A[0], p0, M0.rotation, p, R):
        q = q0.copy()
        for j, v in zip(head + tail, list(th) + list(ts)):
            _set_angle(model, q, j, v)
        out.append(q)
    return out


def _set_angle(model: pin.Model, q: np.ndarray, j: int, angle: float) -> None:
    jm = model.joints[j]
    if jm.nq == 1:
        q[jm.idx_q] = angle
    else:
        q[jm.idx_q:jm.idx_q + 2] = (np.cos(angle), np.sin(angle))
