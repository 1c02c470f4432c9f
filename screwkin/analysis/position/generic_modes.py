"""Every assembly mode of a Stewart-Gough platform by a coefficient-parameter homotopy from a generic
solution set kept per architecture (Morgan and Sommese 1989; Sommese and Wampler 2005, ch. 7).

The platform's closure, whichever way the file writes it (on a floating joint, or carried by one leg
in the tree), is the same system: six distances between ground points A_k and platform points B_k,
in the platform's pose (model.distances.SixDistances).  Its family over the squared leg lengths c is
solved once, at random complex c0, by monodromy (analysis.motion.monodromy): complete when it holds
40 poses (the most for any geometry: Raghavan 1993, Wampler 1996), else when the trace test closes.
That set is kept in the cache folder (files.generic_cache) under the hash of (A, B).  Each query --
the legs' lengths of the inputs -- is one straight segment from c0 to c: by the theory of
coefficient-parameter homotopy every isolated pose of the query is the end of one of these paths
(some paths end at infinity, or at a singular pose).  The real poses are carried back to the file's
joints (the carrying leg's angles by Paden-Kahan subproblems, the other legs by model.legs' lift)
and polished on Pinocchio's closure.

The certificate is checked before it is given: the generic set was complete, no path failed, every
real pose lifted and polished, the poses are distinct (q and -q are one), the complex ones come in
conjugate pairs, their number is at most 40 and each is a simple root; otherwise the result says
which check failed and is not called certified.
"""

from __future__ import annotations

import time
from dataclasses import replace

import numpy as np
import pinocchio as pin

from ...files import generic_cache
from ...model import newton
from ...model.cuts import Assembly
from ...model.distances import SixDistances, chain_angles
from ...model.legs import chain_distance
from ...model.state import KinematicState
from ...model.symmetry import SignGroup
from ..motion.monodromy import MonodromyOptions, Roots, all_roots, to_target

__all__ = ["platform_modes", "Architecture", "architecture", "generic_set"]

BOUND = 40
SOURCE = "Raghavan 1993; Wampler 1996: at most 40"
#: |G(x) - c0| of a cached root, relative: above it the file is not used.
_CACHED_ROOT = 1e-8
#: A polished real pose that moved by more than this (relative to L) from its endpoint is another pose.
_MOVED = 1e-6
#: A complex pose and its conjugate's endpoint agree to this (relative): both are tracked separately.
_CONJUGATE = 1e-6


class Architecture:
    """A platform as six distances: ``A``, ``B`` (6, 3) [m] (A in the world, B in the frame of the
    platform's joint ``joint``), ``r2`` the squared lengths at the inputs [m^2], ``L`` the scale (the
    largest coordinate of A and B);
    ``carrier`` the leg in the tree as (head joints, tail joints, A, B) or None (a floating joint)."""

    def __init__(self, A, B, r2, joint, carrier):
        self.A, self.B, self.r2 = np.asarray(A, float), np.asarray(B, float), np.asarray(r2, float)
        # the scale from the geometry alone: the same platform written either way shares its generic set
        L = self.L = float(max(np.abs(self.A).max(), np.abs(self.B).max(), 1e-9))
        self.joint, self.carrier = joint, carrier
        self.system = SixDistances(self.A / L, self.B / L)
        self.key = generic_cache.key("six distances", [self.A / L, self.B / L])


def architecture(problem, closure, mech):
    """The platform of a closure that known_counts recognized as a Stewart-Gough platform (of ``mech``),
    or None."""
    L = mech.length
    model = problem.model
    if problem.target or any(leg.parent != 0 for leg in closure.legs):
        return None
    joints = {model.frames[leg.other].parentJoint for leg in closure.legs}
    if len(joints) != 1:
        return None
    joint = joints.pop()
    A = [np.asarray(leg.centre, float) for leg in closure.legs]
    B = [np.asarray(model.frames[leg.other].placement.translation, float) for leg in closure.legs]
    r2 = list(np.asarray(closure.r2, float) * L ** 2)
    carrier = None
    if len(closure.legs) == 6:
        if closure.kind[joint] != "F" or model.parents[joint] != 0 or set(closure.slices) != {joint}:
            return None
    elif len(closure.legs) == 5:
        got = chain_distance(model, problem.frozen, joint, L)
        if got is None:
            return None
        a, b = got
        chain = []
        j = joint
        while j > 0:
            chain.append(j)
            j = model.parents[j]
        chain.reverse()
        head, tail = chain[:2], chain[-3:]
        if any(closure.kind[j] != "R" or j not in closure.slices for j in head + tail):
            return None
        if set(closure.slices) != set(head + tail):  # nothing else unknown: the pose sets every joint
            return None
        placement = KinematicState(mech, problem.q_in).joint_placement(joint)
        A.insert(0, np.asarray(a, float))
        B.insert(0, np.asarray(b, float))
        r2.insert(0, float(np.sum((placement.act(np.asarray(b)) - a) ** 2)))
        carrier = (head, tail)
    else:
        return None
    return Architecture(A, B, r2, joint, carrier)


def _group() -> SignGroup:
    return SignGroup(7, [[1, 1, 1, -1, -1, -1, -1]])


def generic_set(arch: Architecture, rng, options: MonodromyOptions):
    """(Roots at generic c0, how its completeness is known or None, where it is kept or None, reused)."""
    system, group = arch.system, _group()
    got = generic_cache.read(arch.key, 7, 6)
    if got is not None:
        c0, X, how, kept = got
        ok = (system.residual(X, c0) <= _CACHED_ROOT * (1 + np.abs(c0).max())) & system.on_variety(X, 1e-8)
        distinct = all(group.match(X[i][None], X[:i], options.same)[0] < 0 for i in range(len(X)))
        whole = len(X) == BOUND if how.startswith("the published bound") else len(X) <= BOUND
        if ok.all() and distinct and whole:
            roots = Roots(X, c0, True, None, "", 0, 0, 0, 0, 0.0, group)
            return roots, how, kept, True
    x0 = system.random_points(rng, 1)
    roots = all_roots(system, group, x0, rng, options, trace_test=False, stop_at=BOUND)
    how = None
    if len(roots.X) == BOUND:
        how = f"the published bound ({SOURCE})"
    elif len(roots.X) < BOUND:
        roots = all_roots(system, group, roots.X[:1], rng, replace(options, budget=options.fallback_budget),
                          seeds=roots.X, trace_test=True, trace_limit=None)
        if roots.complete and len(roots.X) <= BOUND:
            how = f"the trace test (relative singular value {roots.trace:.1g})"
    path = generic_cache.write(arch.key, roots.c0, roots.X, how) if how else None
    return roots, how, path, False


def platform_modes(solver, problem, closure, arch: Architecture, seed: int, options: MonodromyOptions, lift_legs):
    """The modes of a platform (see the module): (modes [(q, Assembly, angle sets, simple)], found, real,
    complex, certificate or None, reason, detail, check) -- analysis.position.certified makes them a
    Certified.  ``lift_legs(x)``: the configuration with the eliminated legs' angles solved from the
    closure's unknowns x, or None."""
    t0 = time.perf_counter()
    rng = np.random.default_rng(seed)
    roots, how, path, reused = generic_set(arch, rng, options)
    t1 = time.perf_counter()
    target = arch.r2 / arch.L ** 2
    ends = to_target(arch.system, roots, target, options)
    group, system = _group(), arch.system
    X, status = ends.X, ends.status
    finite = np.isin(status, ("regular", "singular"))
    safe = np.where(np.isfinite(X), X, 0)
    scale = 1.0 + np.abs(safe).max(axis=1)
    closes = finite & (system.residual(safe, target) <= options.closes * scale ** 2)
    real = closes & (np.abs(safe.imag).max(axis=1) <= options.real * scale)
    distinct, meets = [], np.zeros(len(X), bool)  # one index per pose
    for i in np.flatnonzero(closes):
        j = group.match(X[i][None], X[distinct], options.same)[0] if distinct else -1
        if j >= 0:
            meets[i] = meets[distinct[j]] = True
        else:
            distinct.append(i)
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
    # the leg lengths are real: a complex pose's conjugate is a pose too (a lone one is a real pose
    # misjudged, or a path that went astray)
    cplx = [i for i in distinct if not real[i]]
    lone = sum(group.match(np.conj(X[i])[None], X[[k for k in cplx if k != i]], _CONJUGATE)[0] < 0 for i in cplx) \
        if len(cplx) > 1 else len(cplx)
    failed = int(np.sum(status == "failed"))
    singular = int(np.sum(closes & (status == "singular")))
    check = {"method": "coefficient-parameter homotopy", "generic_set": len(roots.X),
             "generic_set_certified_by": how, "paths": int(len(roots.X)), "failed_paths": failed,
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
    detail = {"roots": int(len(roots.X)), "paths": int(roots.paths + ends.paths), "failed": int(roots.failed + failed),
              "at_infinity": check["at_infinity"], "generic_set": str(path) if path else None,
              "generic_set_reused": reused, "generic_seconds": round(t1 - t0, 3),
              "seconds": round(time.perf_counter() - t0, 3), "lost_polishing": lost}
    return modes, len(distinct), len(modes), n_complex, certificate, "; ".join(why), detail, check


def _onto_joints(solver, problem, closure, arch: Architecture, x, lift_legs):
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

    def rank(q):
        outside = any(n in names for n in solver.outside(solver._wrap(q)))
        dist = float(np.linalg.norm(solver.mech.difference(ref, q))) if ref is not None else 0.0
        return (outside, dist)

    for q in sorted(candidates, key=rank):
        full = lift_legs(closure.from_q(q))
        if full is None:
            continue
        a = newton.polish(problem.system, full, problem.frozen)
        if a.residual > solver.mech.tolerances.closure or not _same_pose(solver.mech, a.q, arch, R, t):
            continue
        q = solver._wrap(a.q)
        return q, Assembly(q, a.residual, a.iterations, "a homotopy's endpoint")
    return None


def _wxyz(q):
    """pin.Quaternion's constructor order (w, x, y, z) from Pinocchio's coefficient order (x, y, z, w)."""
    q = np.asarray(q, float) / np.linalg.norm(q)
    return pin.Quaternion(q[3], q[0], q[1], q[2])


def _same_pose(mech, q, arch, R, t) -> bool:
    M = KinematicState(mech, q).joint_placement(arch.joint)
    return (np.abs(M.translation - t).max() <= _MOVED * arch.L and np.abs(M.rotation - R).max() <= _MOVED)


def _carried(mech, problem, arch: Architecture, R, t) -> list:
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


def _set_angle(model, q, j, angle):
    jm = model.joints[j]
    if jm.nq == 1:
        q[jm.idx_q] = angle
    else:
        q[jm.idx_q:jm.idx_q + 2] = (np.cos(angle), np.sin(angle))
