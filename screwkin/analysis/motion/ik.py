"""Inverse kinematics: the joint values that place an output link at a pose, every branch found
(damped Newton on the loops and the pose from the assembled, the file's and random configurations)."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ...errors import AssemblyError, UsageError
from ...model.closure import ClosureSystem, CutJoint
from ...model.state import KinematicState, angular_loop_joints
from .position import PositionResult, PositionSolver, Solution, outside_limits

__all__ = ["inverse_kinematics"]


def inverse_kinematics(mech, output: str, pose, starts: int = 16, seed: int = 0,
                       position_only: bool = False) -> PositionResult:
    """Joint values (actuated and passive) that place link ``output`` at ``pose``
    (a pinocchio.SE3 in the world), for every distinct assembly found; with ``position_only``
    only its frame's origin at the pose's translation (any orientation).  ``output`` may name
    the tool frame placed by model.state.place_tool (a tool, a named point).

    The target is one more cut joint, a weld (a ball joint for ``position_only``) between a
    ground frame at ``pose`` and the output frame, solved together with the loop closures.  Raises
    AssemblyError (saying how close it got) when the pose is unreachable.
    Solutions are labelled and ordered as those of PositionSolver.solve.
    """
    out_frame = mech.link_frame(output)
    # the target frame (made with the model: adding frames later would outgrow existing Data) placed at
    # the pose in a copy of the model: the mechanism's own model is not changed (threads may share it)
    model = pin.Model(mech.model)
    fid = mech.target_frame
    frame = model.frames[fid]
    frame.placement = pose
    model.frames[fid] = frame
    ctype, dof = ("spherical", 3) if position_only else ("fixed", 0)
    target = CutJoint("target", ctype, dof, fid, out_frame, "world", output, (1.0, 0.0, 0.0))
    # the higher pairs' rows too: without them a gear or cam would be free to slip
    system = ClosureSystem(model, list(mech.cuts) + [target], mech.tolerances, mech.path, extra=mech.extra_rows)
    if not mech.coordinates:
        raise UsageError(f"{mech.path}: the mechanism has no moving joint: nothing to solve for")
    solver = PositionSolver(mech, mech.actuated or [mech.coordinates[0].joint], output=output)
    start_list = solver._starts(starts, seed)
    found, best = solver.distinct(system, start_list)
    if not found:
        xyz = ", ".join(f"{x:.6g}" for x in pose.translation)
        raise AssemblyError(mech.path, best, mech.tolerances.max_iterations, starts=len(start_list),
                            detail=f"the pose of '{output}' at ({xyz}) is unreachable from "
                                   f"{len(start_list)} starting configurations")
    solver.generic(hint=found[0][1])
    ref = solver.reference()
    ref_sig = solver.signature(ref if ref is not None else found[0][1])
    needed = mech.nv - solver.idle_dofs
    sols = []
    for _, q, a in found:
        s = np.linalg.svd(system.jacobian(q), compute_uv=False)
        sigma = float(s[needed - 1] / s[0]) if 0 < needed <= len(s) else 1.0
        state = KinematicState(mech, q)
        outside = outside_limits(mech, q)
        sols.append(Solution(q, solver.joint_values(q), a.residual, a.iterations,
                             sigma < mech.tolerances.singular, sigma, state.frame_pose(out_frame),
                             outside_limits=outside, labels=solver._labels(q, outside),
                             link_angles=solver._link_angles(q), coupled=mech.coupled_values(q) or None,
                             leg_lengths=state.leg_lengths or None))
    sols.sort(key=lambda s: (not s.physical, float(np.linalg.norm(solver.signature(s.q) - ref_sig))))
    return PositionResult({"position": pose.translation.tolist()} if position_only else {"pose": pose.homogeneous.tolist()}, tuple(mech.actuated), tuple(sols), len(start_list),
                          0, (), output, solver.angular_names(), solver._angular_coupled(),
                          angular_loop_joints(mech))
