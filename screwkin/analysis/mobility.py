"""Mobility analysis: counting criteria and the rank of the constraint Jacobian.

The counts (Kutzbach, Gruebler, spherical) come from the topology.  The true
mobility comes from screw theory: at an assembled configuration the rows of the
constraint Jacobian K are the wrenches the cut joints transmit; the joint rates
the loops allow are the null space of K, so ``M = nv - rank K`` where nv counts
the tree-joint velocity coordinates.  The generic rank is the largest rank over
the assembled configuration and a few nearby assembled configurations, so a
file drawn in a singular pose does not change the answer.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
import pinocchio as pin

from ..model.linalg import null_space, rank
from ..model.state import KinematicState
from ..model.topology import Topology
from .local import LocalAnalysis, local_analysis, words as local_words
from .redundancy import Redundancy, redundancy

if TYPE_CHECKING:
    from ..model.mechanism import Mechanism
    from ..tolerances import Tolerances

__all__ = ["MobilityResult", "OutputMotion", "analyze_mobility"]

LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
_FEW_COORDINATES = 60  # above this many joint coordinates, idle motions are analysed at one configuration


@dataclass(frozen=True)
class OutputMotion:
    """What a link can do: the dimension and kind of its twist space.

    label: e.g. "3T" (pure translations), "3R" (rotations about one point),
    "3T1R", "6"; translations: dimension of the pure translations in the
    twist space; rotations: rank of its angular part; twists: a basis of the
    space, each (vx, vy, vz, wx, wy, wz) of the link's origin in world axes.
    point: the link's origin analysed as a point (its velocities only): then
    dimension = translations, rotations = 0 and twists are (vx, vy, vz).
    """

    link: str
    dimension: int
    translations: int
    rotations: int
    label: str
    center: tuple | None
    twists: tuple
    point: bool = False


@dataclass(frozen=True)
class IdleMotion:
    link: str
    dofs: int


@dataclass(frozen=True)
class MobilityResult:
    """Every number of a mobility analysis (the CLI prints and serializes these)."""

    path: str
    topology: Topology
    coordinates: int  # tree-joint velocity coordinates (nv)
    constraint_rows: int
    rank: int
    mobility: int
    overconstraint: int
    idle: tuple  # IdleMotion
    idle_dofs: int
    effective_mobility: int
    actuated: tuple
    actuation_source: str | None
    effective_dofs: int | None
    free_with_inputs_locked: int | None
    classification: str
    notes: tuple
    output: OutputMotion | None
    residual: float
    iterations: int
    samples: int
    q: np.ndarray = field(repr=False, compare=False)
    redundant_constraints: int = 0  # in the detected motion space: M - (its count); 0 = statically determinate
    assembly_start: str = "the file's configuration"  # where the assembly search closed the loops
    starts: int = 1  # starting configurations the search tried
    configuration: dict = field(default_factory=dict)  # joint values of the configuration analysed
    transmissions: tuple = ()  # files.description.Transmission of the inputs driven through a tendon, coupling, gear
    generic_mobility: int | None = None  # coordinates - the generic rank of K: the check on ``mobility``
    local: LocalAnalysis | None = None  # the local analysis at the configuration analysed (analysis.local)
    redundant: Redundancy | None = None  # the redundant constraints by name (analysis.redundancy)
    local_where: str = "the file's configuration"  # where the local analysis was made, in words

    @property
    def kutzbach(self) -> int:
        return self.topology.kutzbach

    @property
    def gruebler(self):
        return self.topology.gruebler

    @property
    def motion_space(self) -> str:
        return self.topology.motion_space


def _body_frames(mech: Mechanism, topo: Topology) -> dict:
    """One body frame per link of the topology (not the ground)."""
    frames = {}
    for link in topo.links:
        if link == topo.ground:
            continue
        frames[link] = mech.link_frame(link)
    return frames


def _joint_geometry_rows(mech: Mechanism, topo: Topology, frames: dict, jac: dict, state: KinematicState) -> list:
    """Rows whose null space is the set of motions keeping every joint's geometry still.

    For each joint and each of its two links: the velocity (seen from that link)
    of a point of the joint (the centre of S and U joints, a point of the axis
    of R joints; for P, C and planar joints only its component across the axis,
    or along the normal, since the point slides), and the rate of each joint
    axis fixed in that link.  A motion that keeps all of them still changes
    nothing in how the links are connected: it can only spin links about lines
    through all their joints, the idle motions.  Higher pairs and screws: the relative twist
    of their two links (rolling, sliding along a profile or turning a screw moves the contact).
    """
    rows = []
    for j in topo.joints:
        if j.type in ("floating",) or j.point is None:
            continue
        p = np.asarray(j.point)
        d = np.asarray(j.direction) if j.direction is not None else None
        if j.type in ("rolling", "gear", "contact", "helical"):
            twists = []
            for link in j.links:
                if link not in frames:
                    twists.append(np.zeros((6, mech.nv)))
                    continue
                J, o = jac[link], state.frame_placement(frames[link]).translation
                twists.append(np.vstack([J[:3] - pin.skew(p - o) @ J[3:], J[3:]]))
            rows.append(twists[1] - twists[0])
            continue
        for side, link in enumerate(j.links):
            if link not in frames:
                continue  # the ground does not move
            J = jac[link]
            o = state.frame_placement(frames[link]).translation
            Jp = J[:3] - pin.skew(p - o) @ J[3:]  # velocity of the point seen from this link
            if j.type in ("prismatic", "cylindrical"):
                rows.append((np.eye(3) - np.outer(d, d)) @ Jp)
            elif j.type == "planar":
                rows.append(d[None, :] @ Jp)
            else:
                rows.append(Jp)
            axes = []
            if j.type in ("revolute", "continuous", "prismatic", "cylindrical", "planar"):
                axes = [d]
            elif j.type == "universal":
                axes = [d if side == 0 else np.asarray(j.direction2)]
            for axis in axes:
                if axis is not None:
                    rows.append(-pin.skew(np.asarray(axis, float)) @ J[3:])
    return rows


def _idle(mech: Mechanism, topo: Topology, frames: dict, q: np.ndarray, V: np.ndarray, output_link: str | None, tol: Tolerances) -> tuple:
    """Idle motions: motions that change no joint's geometry.

    Links joined to the rest by a single joint (free tips such as a serial
    arm's flange) and the output link are excluded: their own motion is an
    output, not an idle one.  Returns (per-link idle dofs, total idle dofs).
    """
    M = V.shape[1]
    if M == 0 or not frames:
        return [], 0, np.zeros((M, 0))
    state = KinematicState(mech, q)
    jac = {k: state.frame_jacobian(f, LWA) for k, f in frames.items()}
    rows = _joint_geometry_rows(mech, topo, frames, jac, state)
    degree = {name: 0 for name in topo.links}
    for j in topo.joints:
        for link in set(j.links):
            degree[link] = degree.get(link, 0) + 1
    for link, deg in degree.items():
        if link in frames and (deg <= 1 or link == output_link):
            rows.append(jac[link])
    A = np.vstack(rows) @ V if rows else np.zeros((0, M))
    I = null_space(A, tol, M)
    idle = []
    if I.shape[1]:
        moves = {link: jac[link] @ V @ I for link in frames}
        # a link takes part in an idle motion when its twist is not negligible
        # next to the largest one (the basis is only as exact as the assembly)
        floor = tol.motion * max(np.linalg.norm(T) for T in moves.values())
        for link, T in moves.items():
            s = np.linalg.svd(T, compute_uv=False)
            k = int(np.sum(s > floor))
            if k:
                idle.append(IdleMotion(link, k))
    return idle, I.shape[1], I


def _point_motion(link: str, T, tol: Tolerances) -> OutputMotion:
    """What the origin of a link can do as a point: the rank of its velocities."""
    dim = rank(T[:3], tol)
    if dim == 0:
        return OutputMotion(link, 0, 0, 0, "0 (immobile)", None, (), True)
    U, _, _ = np.linalg.svd(T[:3], full_matrices=False)
    return OutputMotion(link, dim, dim, 0, f"{dim}T", None, tuple(tuple(c) for c in U[:, :dim].T), True)


def _output_motion(link: str, T: np.ndarray, tol: Tolerances, origin: np.ndarray) -> OutputMotion:
    dim = rank(T, tol)
    if dim == 0:
        return OutputMotion(link, 0, 0, 0, "0 (immobile)", None, ())
    U, s, _ = np.linalg.svd(T, full_matrices=False)
    basis = U[:, :dim]
    r = rank(basis[3:], tol)
    t = dim - r
    center = None
    if dim == 6:
        label = "6"
    elif t == 0:
        # pure rotations about one point c: v_o + w x (c - o) = 0 for every twist
        A = np.vstack([pin.skew(basis[3:, k]) for k in range(dim)])
        b = np.concatenate([-basis[:3, k] for k in range(dim)])
        x, *_ = np.linalg.lstsq(A, b, rcond=None)
        scale = max(np.linalg.norm(basis[:3]), 1.0)
        if np.linalg.norm(A @ x - b) < tol.motion * scale:
            label = f"{r}R"
            # for one rotation the point is any point of the axis: take the nearest to the origin
            center = tuple(np.asarray(origin) + x)
        elif dim == 1:
            w, v = basis[3:, 0], basis[:3, 0]
            label = f"1H (screw, pitch {w @ v / (w @ w):.4g} m/rad)"
        else:
            label = f"{r}R (screw motions)"
    else:
        label = (f"{t}T" if t else "") + (f"{r}R" if r else "")
    return OutputMotion(link, dim, t, r, label, center, tuple(tuple(col) for col in basis.T))


def _classification(n: int, m: int, eff: int, overconstraint: int, topo: Topology, M: int) -> tuple:
    """The classification and notes; a structure (no effective DOF) is statically determinate
    or not in its detected motion space: a planar triangle is determinate in the plane
    (Gruebler 0 = M), although 3 of its 5 spatial constraint rows are redundant."""
    notes = []
    lam_count = topo.count_in_motion_space
    redundant = M - lam_count
    space = topo.motion_space
    crit = {"planar": "Gruebler (planar) count", "spherical": "spherical count"}.get(space, "Kutzbach count")
    where = f" in the {'plane' if space == 'planar' else 'sphere'}" if space != "spatial" else ""
    if n == 0:
        kind = (f"statically determinate structure{where}" if redundant <= 0 else
                f"statically indeterminate structure{where} ({redundant} redundant constraint"
                f"{'s' if redundant > 1 else ''})")
    elif m == 0:
        kind = f"mechanism with {n} degree{'s' if n > 1 else ''} of freedom (no actuated joints declared)"
    elif m == n and eff == n:
        kind = "constrained mechanism (properly actuated)"
    elif m == n:
        kind = f"improperly actuated: {m} inputs but they control only {eff} of the {n} degrees of freedom"
    elif m < n:
        kind = f"unconstrained (under-actuated): {m} input{'s' if m > 1 else ''} for {n} degrees of freedom"
    else:
        kind = f"redundantly actuated: {m} inputs for {n} degree{'s' if n > 1 else ''} of freedom"
    if lam_count != M:
        why = []
        if redundant > 0 and M > 0 and lam_count <= 0:
            why.append(f"the mechanism is overconstrained ({redundant} redundant constraint"
                       f"{'s' if redundant > 1 else ''}{where}: its special geometry lets it move although the count "
                       "says it cannot)")
        elif redundant > 0:
            why.append(f"{redundant} constraint{'s are' if redundant > 1 else ' is'} redundant{where}: the count "
                       f"takes {'them' if redundant > 1 else 'it'} as independent")
        notes.append(f"The {crit} gives {lam_count} but the screw-theory mobility is {M}"
                     + (": " + "; ".join(why) if why else "") + ".")
    if space != "spatial" and topo.kutzbach != M:
        notes.append(f"The spatial Kutzbach count ({topo.kutzbach}) does not apply: the mechanism is {space}"
                     + (f" (spatially {overconstraint} of the constraint rows are redundant; {where.strip()} "
                        f"{max(redundant, 0)})." if overconstraint != redundant else "."))
    if n != M:
        notes.append(f"{M - n} of the {M} degrees of freedom are idle (a link turning on itself); "
                     f"{n} remain effective.")
    if n < 0:  # pragma: no cover - rank-based mobility is never negative
        kind = "statically indeterminate structure"
    return kind, tuple(notes)


def analyze_mobility(mech: Mechanism, output: str | None=None, seed: int = 0, point: bool = False, at=None,
                     suggest: bool = False, names: bool = False, progress=None) -> MobilityResult:
    """Mobility of ``mech`` (see the module docstring); output names a link, point analyses
    its origin as a point (3 translations) instead of its full motion.  The mobility reported is the
    finite mobility at the configuration ``at`` (default: where the assembly search first closed the
    loops, the file's configuration when it closes them), decided by analysis.local, with the generic
    rank as its check (``generic_mobility``); with ``names`` the redundant constraints by name
    (analysis.redundancy, ``redundant``), with ``suggest`` also the joints that make the model exactly
    constrained.  Kept in ``mech.cache``.  progress: told of the local analysis' work (analysis.local)."""
    key = ("mobility", tuple(mech.actuated), output, seed, point,
           None if at is None else np.asarray(at, float).tobytes(), suggest, names)
    if key not in mech.cache:
        mech.cache[key] = _analyze(mech, output, seed, point, at, suggest, names, progress)
    return mech.cache[key]


def _local_notes(local: LocalAnalysis, where: str, M_generic: int, generic_rank: int, samples: int) -> tuple:
    """Why the mobility reported (the local analysis' finite mobility at ``where``) is not the generic one."""
    if local.finite_mobility is None or local.finite_mobility == M_generic:
        return ()
    return (f"The generic rank of K ({generic_rank}, the largest over {samples} assembled configurations) would give "
            f"mobility {M_generic}; the mobility reported is the finite mobility at {where}, {local.finite_mobility}: "
            f"{local_words(local)}"
            + (" (the configurations of the larger rank are near solutions the closure tolerance accepts, or "
               "another branch)" if local.finite_mobility < M_generic else
               " (this configuration is on a branch of higher mobility than the generic one)") + ".",)


def _sample(mech: Mechanism, q: np.ndarray, output: str | None, out_frame: int | None, point: bool,
            act_idx: np.ndarray, tol: Tolerances) -> tuple:
    """One assembled configuration's ranks: ((rank of K, the output's motion's dimension, the inputs' effective
    rank), q, K, rank of K, V (K's null space), the output's motion, the inputs' effective rank)."""
    K = mech.closure.jacobian(q)
    rk = rank(K, tol)
    V = null_space(K, tol, mech.nv) if K.size else np.eye(mech.nv)
    out = None
    if output is not None and out_frame is not None:
        state = KinematicState(mech, q)
        T = state.frame_jacobian(out_frame, LWA) @ V
        out = _point_motion(output, T, tol) if point else _output_motion(
            output, T, tol, state.frame_placement(out_frame).translation)
    eff = rank(V[act_idx], tol) if len(act_idx) else None
    return (rk, out.dimension if out else 0, eff or 0), q, K, rk, V, out, eff


def _generic(mech: Mechanism, candidates: list[tuple], frames: dict, output_link: str | None,
             tol: Tolerances) -> tuple:
    """Of the sampled configurations, one of the largest ranks with the fewest idle motions: (q, K, rank of K,
    mobility, V, idle motions, their count, their basis, the output's motion, the inputs' effective rank)."""
    top = max(c[0] for c in candidates)
    candidates = [c for c in candidates if c[0] == top]
    if mech.nv > _FEW_COORDINATES:  # the idle motions of a big mechanism: at one generic configuration
        candidates = candidates[:1]
    best = None
    for _, q, K, rk, V, out, eff in candidates:
        idle, idle_total, I = _idle(mech, mech.topology(q), frames, q, V, output_link, tol)
        if best is None or idle_total < best[6]:
            best = (q, K, rk, V.shape[1], V, idle, idle_total, I, out, eff)
    assert best is not None  # (the candidates of the top ranks are never none)
    return best


def _analysis_notes(mech: Mechanism, local: LocalAnalysis, where: str, M_generic: int, rk: int, samples: int,
                    assembly: Any, at: np.ndarray | None, own: bool) -> tuple[str, ...]:
    """The notes on the transmissions, the local analysis (where it is not the generic one) and an assembly
    that first closed at a singular configuration."""
    notes: tuple[str, ...] = ()
    for t in mech.transmissions():
        notes += (f"Input {t.text()}: its coordinate is {t.joint}.",)
    if local.kind != "regular" or local.rank_drop or local.finite_mobility != M_generic:
        notes += _local_notes(local, where, M_generic, rk, samples)
        if local.rank_drop:
            notes += ("The idle motions, the output's motion and the counts use assembled configurations of the "
                      "generic rank.",)
    first_singular, first_rank, generic_rank = mech.first_assembly_singular
    if first_singular and at is None and not own:
        notes += (f"At {assembly.start}, where the loops first closed, the mechanism is singular or on another "
                  f"branch (rank of K {first_rank} < {generic_rank}: instantaneous mobility {mech.nv - first_rank} "
                  f"there); the analysis uses assembled configurations of the generic rank.",)
    return notes


def _analyze(mech: Mechanism, output: str | None, seed: int | None, point: bool, at: np.ndarray | None = None,
             suggest: bool = False, names: bool = False,
             progress: Callable[..., object] | None = None) -> MobilityResult:
    tol = mech.tolerances
    out_frame = mech.link_frame(output) if output is not None else None
    assembly, configs = mech.generic_configurations(seed=seed)
    topo = mech.topology(configs[0])
    frames = _body_frames(mech, topo)
    output_link = None
    if output is not None:
        output_link = next((l for l, m in topo.link_members.items() if output in m), output)
    act_idx = mech.velocity_indices(mech.actuated)
    candidates = [_sample(mech, q, output, out_frame, point, act_idx, tol) for q in configs]
    q, K, rk, M, V, idle, idle_total, I, out, eff = _generic(mech, candidates, frames, output_link, tol)
    M_generic = M
    # where the mobility is decided: the configuration given; else the file's own configuration when it closes
    # the loops; else (the search closed them from another start, an arbitrary point of any branch) the
    # configuration of the generic rank the rest of the analysis uses
    own = assembly.start == "the file's configuration"
    where_q = np.asarray(at, float) if at is not None else (assembly.q if own else q)
    where = ("the configuration given" if at is not None else assembly.start if own else
             "an assembled configuration of the generic rank")
    local_where = where
    local = local_analysis(mech, where_q, generic_rank=rk, progress=progress)
    if local.finite_mobility is not None:
        M = local.finite_mobility
        idle_total = min(idle_total, M)
    n = M - idle_total
    m = len(act_idx)
    locked = None
    if m:
        # motions left with the inputs locked, beyond the idle ones
        L = null_space(V[act_idx], tol, M)
        locked = rank(np.hstack([L, I]), tol) - idle_total if L.shape[1] else 0
    overconstraint = K.shape[0] - rk
    kind, notes = _classification(n, m, eff if eff is not None else 0, overconstraint, topo, M)
    if local.kind == "shaky":
        kind = (f"shaky structure: infinitesimally mobile ({local.infinitesimal_mobility} "
                f"instantaneous degree{'s' if local.infinitesimal_mobility > 1 else ''} of freedom), finitely rigid")
    if m and locked:
        notes += (f"With the inputs locked the mechanism can still move ({locked} degree{'s' if locked > 1 else ''} of freedom).",)
    notes += _analysis_notes(mech, local, where, M_generic, rk, len(configs), assembly, at, own)
    found = redundancy(mech, q, suggest_fix=suggest) if names or suggest else None
    return MobilityResult(
        path=mech.path,
        topology=topo,
        coordinates=mech.nv,
        constraint_rows=K.shape[0],
        rank=rk,
        mobility=M,
        overconstraint=overconstraint,
        idle=tuple(idle),
        idle_dofs=idle_total,
        effective_mobility=n,
        actuated=tuple(mech.actuated),
        actuation_source=mech.actuation_source,
        effective_dofs=eff,
        free_with_inputs_locked=locked,
        classification=kind,
        notes=notes,
        output=out,
        residual=assembly.residual,
        iterations=assembly.iterations,
        samples=len(configs),
        q=q,
        redundant_constraints=max(M - topo.count_in_motion_space, 0),
        assembly_start=assembly.start,
        starts=assembly.starts,
        configuration=mech.joint_values(q),
        transmissions=mech.transmissions(),
        generic_mobility=M_generic,
        local=local,
        redundant=found,
        local_where=local_where,
    )
