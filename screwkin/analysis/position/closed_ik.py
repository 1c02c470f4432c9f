"""Inverse kinematics in closed form, where the mechanism's structure gives one: a parallel platform whose
every leg's length follows from the platform's pose (model.leg_chains: the leg lengths, then each leg's
joint angles from its direction), and a six-revolute arm whose last three axes meet (Pieper:
analysis.position.pieper).  None where neither applies: analysis.position.ik then searches.

A platform's answer is the physical solution first (every leg extended, each leg's angle set within the
joint limits where one exists), then each leg's other branch beside it (that leg reversed through its
pivot, the others as in the first): every combination of the legs' branches is a solution too
(2 per leg), listed where there are at most LISTED (a 3-RPR's 8), else counted.  An arm's answer is
every distinct joint solution (up to 8, the others complex, counted).
"""

from __future__ import annotations

import itertools
import time
from dataclasses import replace

import numpy as np
import pinocchio as pin

from ...errors import AssemblyError
from ...model.cuts import Assembly
from ...model.leg_chains import best_set, leg_poses, platform_of, set_free, set_leg
from ...model.manifold import set_continuous_angle
from ...model.state import KinematicState, angular_loop_joints, frame_parent
from .certified import ModeCount
from .pieper import BOUND, pieper, wrist_arm
from .solution import PositionResult
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism
    from screwkin.analysis.position.position import PositionSolver
    from screwkin.model.leg_chains import Platform

__all__ = ["closed_form_ik", "LISTED"]

LISTED = 8  # a platform's combinations of leg branches listed in full up to this many


def closed_form_ik(solver: PositionSolver, output: str, pose: pin.SE3):
    """The PositionResult of ``output``'s frame at ``pose`` (a pinocchio.SE3) in closed form, or None
    where the mechanism has none (see the module).  Raises AssemblyError where the closed form shows the
    pose unreachable (a leg too short, a pivot's plane left)."""
    mech = solver.mech
    out_frame = mech.link_frame(output)
    joint, placement = frame_parent(mech, out_frame)
    start = time.perf_counter()
    platform = platform_of(mech, joint)
    if platform is not None:
        return _platform(solver, output, out_frame, platform, pose * placement.inverse(), pose, start)
    arm = wrist_arm(mech, joint, placement)
    if arm is not None:
        return _arm(solver, output, out_frame, arm, pose, start)
    return None


def _result(solver: PositionSolver, output: str, pose: pin.SE3, sols: list, count: int) -> PositionResult:
    mech = solver.mech
    return PositionResult({"pose": pose.homogeneous.tolist()}, tuple(mech.actuated), tuple(sols), 0, 0, (),
                          output, solver.angular_names(), solver._angular_coupled(), angular_loop_joints(mech),
                          modes=count)


def _solution(solver: PositionSolver, q: np.ndarray, out_frame: int, residual: float, spelled: bool=False):
    mech = solver.mech
    sol = solver.solution(q, Assembly(q, residual, 0), simple=True, spelled=spelled)
    if solver.output_frame == out_frame and sol.output_pose is not None:  # read there already
        return replace(sol, simple=True)
    return replace(sol, output_pose=KinematicState(mech, sol.q).frame_pose(out_frame), simple=True)


def _residual(mech: Mechanism, q: np.ndarray, out_frame: int, pose: pin.SE3) -> float:
    """The loops' residual and the output frame's distance from the pose (m and rad together)."""
    loops = float(np.linalg.norm(mech.closure.residual(q))) if mech.cuts else 0.0
    at = KinematicState(mech, q).frame_pose(out_frame)
    err = pin.log6(pose.inverse() * pin.SE3(at[:3, :3], at[:3, 3])).vector
    return max(loops, float(np.linalg.norm(err)))


def _platform(solver: PositionSolver, output: str, out_frame: int, platform: Platform, P: pin.SE3, pose: pin.SE3, start: float) -> PositionResult | None:
    mech, model = solver.mech, solver.mech.model
    legs = []
    for leg in platform.legs:
        poses, why, gap = leg_poses(platform, leg, P)
        if not poses:
            xyz = ", ".join(f"{v:.6g}" for v in pose.translation)
            raise AssemblyError(mech.path, gap, 0, proved=True, reason=why,
                                message=f"the pose of '{output}' at ({xyz}) is unreachable: {why} (closed form: "
                                        "each leg's length follows from the pose; no search)")
        legs.append(poses)
    ref = mech.neutral()
    q = set_free(platform, model, np.array(ref, float), P)
    chosen = []
    for poses in legs:
        first = poses[0]  # the extended root
        s = best_set(mech, ref, first)
        set_leg(model, q, first, s)
        chosen.append((first, s))
    tol = mech.tolerances
    res = _residual(mech, q, out_frame, pose)
    if res > tol.closure * 100 + tol.closed_form:
        return None  # a loop joint the legs do not close (a universal joint's angle): the general method
    combos = int(np.prod([len(p) for p in legs]))
    if combos <= LISTED:  # every combination of the legs' branches
        picks = [c for c in itertools.product(*[range(len(p)) for p in legs]) if any(c)]
    else:  # each leg's other branches beside the physical solution
        picks = [tuple(i if m == k else 0 for m in range(len(legs))) for k, p in enumerate(legs)
                 for i in range(1, len(p))]
    qs = [(q, res)]
    for pick in picks:
        q2 = np.array(q)
        for i, poses in zip(pick, legs):
            if i:
                set_leg(model, q2, poses[i], best_set(mech, ref, poses[i]))
        r2 = _residual(mech, q2, out_frame, pose)
        if r2 <= tol.closure * 100 + tol.closed_form:
            qs.append((q2, r2))
    # the reference configuration's search starts from the physical solution, and no random starts: every
    # branch of the legs is in the closed form, and away from singularities each has the same generic ranks
    solver.generic(hint=q, starts=0)
    # each leg in its angle set with the fewest joints outside the limits (best_set): spelled already
    sols = [_solution(solver, qq, out_frame, r, spelled=True) for qq, r in qs]
    ref_sig = solver.signature(ref)
    if combos <= LISTED:  # all of them: nearest the reference first (each leg's other branch: in leg order)
        sols[1:] = sorted(sols[1:], key=lambda s: (not s.physical,
                                                   float(np.linalg.norm(solver.signature(s.q) - ref_sig))))
    sets = int(np.prod([len(p[0].sets) for p in legs]))
    where = "a floating joint holds the platform" if platform.free is not None else \
        f"{platform.legs[0].name} holds the platform in the tree"
    count = ModeCount(combos, True, "closed form (legs)", combos, 0,
                      f"closed form: each leg's length follows from the pose ({len(legs)} legs; {where})",
                      detail={"legs": [p[0].leg.name for p in legs], "branches_per_leg": [len(p) for p in legs],
                              "leg_joints": [[model.names[j] for j in p[0].leg.joints] for p in legs],
                              "listed": len(sols),
                              "angle_sets": sets, "seconds": round(time.perf_counter() - start, 4)})
    return _result(solver, output, pose, sols, count)


def _arm(solver: PositionSolver, output: str, out_frame: int, arm, pose: pin.SE3, start: float):
    mech, model = solver.mech, solver.mech.model
    sets, _, why, stretched = pieper(arm, pose, mech.tolerances)
    if why:
        return None  # the wrist centre on the first or second axis (a continuum): the general method
    lo, hi = model.lowerPositionLimit, model.upperPositionLimit
    qs = []
    for s in sets:
        q = np.array(mech.neutral(), float)
        for j, t in zip(arm.joints, s):
            jm = model.joints[j]
            if jm.nq == 2:
                set_continuous_angle(q, jm.idx_q, t)
                continue
            i = jm.idx_q
            for shift in (0.0, 2 * np.pi, -2 * np.pi):  # within the limits where a turn puts it there
                if np.isfinite(lo[i]) and lo[i] <= t + shift <= hi[i]:
                    t = t + shift
                    break
            q[i] = t
        qs.append(q)
    if not qs:
        xyz = ", ".join(f"{v:.6g}" for v in pose.translation)
        raise AssemblyError(mech.path, np.inf, 0, starts=0,
                            message=f"the pose of '{output}' at ({xyz}) is unreachable: all {BOUND} joint solutions "
                                    "of the closed form (Pieper: the last three axes meet) are complex; no search")
    solver.generic(starts=0)  # an arm has no loops: no random starts for their branches
    sols = [_solution(solver, q, out_frame, _residual(mech, q, out_frame, pose)) for q in qs]
    sols = [replace(s, continuum=True, singular=True) if st else s for s, st in zip(sols, stretched)]
    ref_sig = solver.signature(mech.neutral())
    sols.sort(key=lambda s: (not s.physical, float(np.linalg.norm(solver.signature(s.q) - ref_sig))))
    c = ", ".join(f"{v:.6g}" for v in arm.centre)
    names = [model.names[j] for j in arm.joints]
    n_cont = sum(stretched)
    count = ModeCount(BOUND, True, "closed form (Pieper)", len(sols), BOUND - len(sols) - n_cont,
                      f"closed form (Pieper: last three axes meet at ({c}) m at the file's configuration; "
                      f"at most {BOUND} solutions)"
                      + (f"; {n_cont} of them a continuum: the wrist stretched ({names[3]} and {names[5]} about "
                         f"one line, only their sum fixed), shown with {names[3]} = 0" if n_cont else ""),
                      detail={"wrist_centre": arm.centre.tolist(), "stretched": n_cont,
                              "seconds": round(time.perf_counter() - start, 4)})
    return replace(_result(solver, output, pose, sols, count), free_dofs=int(bool(sols) and all(stretched)))

