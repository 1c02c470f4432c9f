"""Inverse kinematics: the joint values that place an output link at a pose, every branch found
(damped Newton on the loops and the pose from the assembled, the file's and random configurations)."""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ...errors import AssemblyError, UsageError
from ...model.kernel.algebraic import algebraic_obstacle
from ...model.kernel.closure import ClosureSystem
from ...model.cuts import CutJoint
from ...model.geometry import wrap_angle
from ...model.linalg import rank
from ...model.state import KinematicState, angular_loop_joints, model_with_output
from ...model.topology import frame_link
from . import certified
from .closed_ik import closed_form_ik
from .position import PositionSolver
from .solution import PositionResult
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism

__all__ = ["inverse_kinematics", "Branches", "branches"]


def inverse_kinematics(mech: Mechanism, output: str, pose, starts: int = 16, seed: int = 0,
                       position_only: bool = False, method: str = "auto") -> PositionResult:
    """Joint values (actuated and passive) that place link ``output`` at ``pose``
    (a pinocchio.SE3 in the world), for every distinct assembly found; with ``position_only``
    only its frame's origin at the pose's translation (any orientation).  ``output`` may name
    the tool frame placed by model.state.place_tool (a tool, a named point).

    The target is one more cut joint, a weld (a ball joint for ``position_only``) between a
    ground frame at ``pose`` and the output frame, solved together with the loop closures.  Raises
    AssemblyError (saying how close it got) when the pose is unreachable.
    Solutions are labelled and ordered as those of PositionSolver.solve.  ``method`` "auto": in closed
    form where the mechanism gives one (a full pose of a platform whose legs' lengths follow from it, a
    6R arm whose last three axes meet: analysis.position.closed_ik; its ``modes.method`` starts with
    "closed form"), else every solution by homotopy continuation where the closure is polynomial
    (analysis.position.certified: certified by the trace test or a published count), random starts added where it is not
    certified; "starts": damped Newton from random starts only.
    """
    out_frame = mech.link_frame(output)
    if method == "auto" and not position_only and mech.coordinates:
        closed = closed_form_ik(PositionSolver(mech, mech.actuated or [mech.coordinates[0].joint], output=output),
                                output, pose)
        if closed is not None:
            return closed
    # the target frame (made with the model: adding frames later would outgrow existing Data) placed at
    # the pose in a copy of the model, with the output frame where place_tool put it: the mechanism's own
    # model is not changed (threads may share it)
    model = model_with_output(mech)
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
    done, found, best = None, [], np.inf
    why = algebraic_obstacle(model, system.cuts, mech.extra_rows, mech.couplings)
    if method != "starts":
        ref = solver.reference()
        problem = certified.Problem(model, system.cuts, system, np.zeros(0, int),
                                    mech.neutral() if ref is None else ref, ref, target=not position_only)
        done = certified.Search([], [], None, f"the closure is not polynomial: {why}") if why else \
            certified.search(solver, {}, seed, problem)
        found = list(done.found)
    if not done or not done.complete:
        more, best = solver.distinct(system, start_list)
        found = certified.join(solver, found, more)
    else:
        start_list = []
    count = done.count if done is not None and done.complete else certified.count_after_starts(done, found, len(start_list))
    if not found:
        xyz = ", ".join(f"{x:.6g}" for x in pose.translation)
        raise AssemblyError(mech.path, best, mech.tolerances.max_iterations, starts=len(start_list),
                            detail=f"the pose of '{output}' at ({xyz}) is unreachable from "
                                   f"{len(start_list)} starting configurations")
    solver.generic(hint=found[0][1])
    ref = solver.reference()
    ref_sig = solver.signature(ref if ref is not None else found[0][1])
    needed = mech.nv - solver.idle_dofs
    # what the target leaves free beyond the idle DOFs (a position alone on a planar platform: its turn)
    jacobians = [system.jacobian(q) for _, q, _ in found]
    free = max(needed - max(rank(J, mech.tolerances) for J in jacobians), 0)
    sols = []
    info = dict(enumerate(done.info)) if done is not None else {}
    for k_found, ((_, q, a), J) in enumerate(zip(found, jacobians)):
        s = np.linalg.svd(J, compute_uv=False)
        k = needed - free  # a continuum left by the target is no singularity: the rank it keeps
        sigma = float(s[k - 1] / s[0]) if 0 < k <= len(s) else 1.0
        sets, simple = info.get(k_found, (None, None))
        # every quantity as solve reports it (loop joints, links, leg lengths), singular by the ik system
        sol = solver.solution(q, a, sets=sets, simple=True)
        sols.append(replace(sol, singular=sigma < mech.tolerances.singular and not simple, sigma_min=sigma,
                            output_pose=KinematicState(mech, q).frame_pose(out_frame), sigmas=None, simple=simple))
    sols.sort(key=lambda s: (not s.physical, float(np.linalg.norm(solver.signature(s.q) - ref_sig))))
    return PositionResult({"position": pose.translation.tolist()} if position_only else {"pose": pose.homogeneous.tolist()}, tuple(mech.actuated), tuple(sols), len(start_list),
                          free, (), output, solver.angular_names(), solver._angular_coupled(),
                          angular_loop_joints(mech), modes=count)


@dataclass(frozen=True)
class Branches:
    """How many inverse-kinematics branches a result holds, against how many there can be.

    found:   distinct solutions found;
    legs:    per leg (a chain of links between the ground and the output link), its joint names and
             how many distinct settings of them the solutions hold;
    at_most: the most there can be, where known (every leg a planar dyad: two circle or line
             intersections at most, one with two sliders), else None;
    why:     that bound in words ("" when unknown)."""

    found: int
    legs: tuple  # ((joint names), distinct settings found, at most or None)
    at_most: int | None
    why: str

    @property
    def complete(self) -> bool:
        """Every branch the bound allows was found."""
        return self.at_most is not None and self.found >= self.at_most


def branches(mech: Mechanism, res: PositionResult) -> Branches:
    """Count the branches of an inverse-kinematics result leg by leg.  A leg is a connected set of
    links once the ground and the output link are taken away; with the output placed, each leg's
    joints are solved on their own, so the branches are the combinations of the legs' settings.
    A planar leg of three one-DOF joints (a dyad: two unknowns) has at most two closures (one when
    two of its joints slide)."""
    n = len(res.solutions)
    c = res.modes
    if c is not None and c.method == "closed form (legs)":  # every combination of the legs' branches exists
        legs = tuple((tuple(j), k, k) for j, k in zip(c.detail["leg_joints"], c.detail["branches_per_leg"]))
        return Branches(c.found, legs, c.found, "closed form: each leg extended or reversed through its pivot")
    if c is not None and c.method == "closed form (Pieper)":
        return Branches(n, (), n, "closed form (Pieper): every real joint solution")
    import networkx as nx

    if res.free_dofs or not res.output or not res.solutions:
        return Branches(n, (), None, "")
    topo = mech.topology(res.solutions[0].q)
    member_of = {m: name for name, members in topo.link_members.items() for m in members}
    out = member_of.get(frame_link(mech, res.output))
    graph = nx.Graph()
    graph.add_nodes_from(lk for lk in topo.links if lk not in (topo.ground, out))
    graph.add_edges_from(j.links for j in topo.joints if all(lk in graph for lk in j.links))
    legs = []
    tol = mech.tolerances.geometry
    for comp in sorted(nx.connected_components(graph), key=lambda c: min(topo.links.index(lk) for lk in c)):
        joints = [j for j in topo.joints if set(j.links) & comp]
        names = [m for j in joints for m in j.members if m in res.solutions[0].joints]
        angular = np.array([m in res.angular or m in res.angular_loop for m in names], bool)
        settings = []
        for s in res.solutions:
            v = np.array([s.joints[m] for m in names])
            d = [v - w for w in settings]
            if not any(np.all(np.abs(np.where(angular, wrap_angle(e), e)) <= tol) for e in d):
                settings.append(v)
        dyad = (topo.motion_space == "planar" and len(joints) == 3
                and all(j.dof == 1 and j.type in ("revolute", "continuous", "prismatic") for j in joints))
        most = (1 if sum(j.type == "prismatic" for j in joints) >= 2 else 2) if dyad else None
        legs.append((tuple(names), len(settings), most))
    if len(legs) < 2 or any(m is None for _, _, m in legs):
        return Branches(n, tuple(legs), None, "")
    return Branches(n, tuple(legs), int(np.prod([m for _, _, m in legs])),
                    "each leg a planar dyad: two circle or line intersections at most")

