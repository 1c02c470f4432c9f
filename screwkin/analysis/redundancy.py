"""The redundant constraints of a mechanism, by name: which wrenches the joints carry that statics
cannot determine, which rows of K they are, and which joints would make the model exactly constrained.

At an assembled configuration the rows of the constraint Jacobian K are constraint wrenches
(model.kernel.closure: each row's wrench on F2's link is ``row_wrenches``).  A left null vector lambda of
K (lambda^T K = 0) is a set of loads the cut joints can carry against each other with no load
applied and no effort at any joint: a self-stress, statically indeterminate.  The left null space
(SVD, with screwkin's rank tolerance) gives a basis; each vector's rows of one cut joint sum to the
wrench that joint carries, here written as a 6-vector (force, moment about the world origin) in the
ground frame, and in words in the joint's own directions (its axis and the world axes across it).

The rows a simulator would remove are named as Chrono does: a column-pivoted QR of K^T
(scipy.linalg.qr, pivoting) puts rank(K) independent rows first; the rest are the redundant rows
(their labels as model.kernel.closure.row_labels writes them).  Their number is the left null space's.

A suggestion makes the model exactly constrained as designers do in Adams: each redundant wrench is
released by giving a joint a freedom it does work against (a revolute made spherical, universal or
cylindrical), chosen so that every freedom added releases one redundancy (the rank of the pairing of
the redundant wrenches with the added twists grows by one per freedom): then the overconstraint is 0
and the mobility unchanged.  Cut joints are changed first, then unactuated tree joints next to the
ground, then the others.  The suggestion is checked by building the changed mechanism (a tree joint
as the sidecar's SPHERICAL or UJOINT_ab, a cut joint's type) and analysing its mobility again.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, replace

import numpy as np

from ..errors import ScrewkinError
from ..model._pin import joint_axis
from ..model.geometry import perpendicular_basis
from ..model.kernel.scaling import dimensionless
from ..model.linalg import null_space, rank
from ..model.loader import rebuild
from ..model.state import KinematicState
from .loop_series import loop_system, split, subalgebra
from .screws import screw_of
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism
    from screwkin.model.cuts import CutJoint
    from screwkin.tolerances import Tolerances
    from screwkin.analysis.loop_series import LoopSystem

__all__ = ["JointRedundancy", "Suggestion", "Redundancy", "redundancy", "suggest", "CANONICAL"]

#: The canonical wrenches of a joint, in its directions (e3 its axis, e1, e2 across): names as said.
CANONICAL = ("force along {1}", "force along {2}", "force along {3}", "moment about {1}", "moment about {2}",
             "moment about {3}")


@dataclass(frozen=True)
class JointRedundancy:
    """What one joint (a cut joint, an MJCF equality, a coupling) carries that statics cannot give.

    joint: its name as the file writes it; what: "loop joint", "connect", "weld", "coupling";
    rows: its rows of K, of which ``count`` are redundant;
    wrenches: a basis of the redundant wrenches it carries, each (fx, fy, fz, mx, my, mz) with the
    moment about the world origin, world axes; at: the joint's point (F2's origin) [m];
    named: the basis as canonical wrenches in its directions when it is one (else ());
    words: what it carries, in words; why: "planar", "spherical" or "overconstrained"."""

    joint: str
    what: str
    rows: int
    count: int
    wrenches: tuple
    at: tuple
    named: tuple
    words: str
    why: str


@dataclass(frozen=True)
class Suggestion:
    """Joints to change so that the model is exactly constrained: changes (joint, new type, words),
    and what the changed model gives: its mobility and overconstraint (None when not built)."""

    changes: tuple
    words: str
    mobility: int | None
    overconstraint: int | None
    checked: str


@dataclass(frozen=True)
class Redundancy:
    """The redundant constraints at one configuration (see the module docstring)."""

    count: int  # dimension of the left null space of K (rows - rank)
    basis: tuple  # per vector: {joint: (fx, fy, fz, mx, my, mz)} at the world origin
    rows: tuple  # per vector: {row label: coefficient}
    joints: tuple  # JointRedundancy
    qr_redundant_rows: tuple  # the row labels a column-pivoted QR of K^T puts last
    qr_rank: int
    suggestion: Suggestion | None


def _left_null(mech: Mechanism, q: np.ndarray) -> tuple:
    """(K scaled (positions / L), lambda basis in K's own units (columns), labels)."""
    K = mech.closure.jacobian(q)
    L = mech.length
    rows = mech.closure.position_rows
    Ks = dimensionless(K, rows, mech.translational, L)
    Lam = null_space(Ks.T, mech.tolerances, Ks.shape[0]) if Ks.size else np.zeros((Ks.shape[0], 0))
    Lam = Lam.copy()
    Lam[rows] /= L  # lambda^T K = 0 in K's own units
    return Ks, Lam, mech.closure.row_labels()


def _cut_words(mech: Mechanism) -> dict:
    """cut joint or coupling name -> (what it is in the file's words)."""
    out = {}
    for c in mech.spec.cut_joints:
        if c.source == "mjcf":
            out[c.name] = "connect" if c.type == "spherical" else "weld"
        else:
            out[c.name] = "loop joint"
    return out


def _directions(cut: CutJoint, state: KinematicState, tol: Tolerances) -> tuple:
    """(e1, e2, e3, names): a joint's directions: e3 its axis when it has one ("the axis" and, when it is
    a world axis, its letter), e1 e2 across it (world axes when they are); else the world axes."""
    letters = {0: "x", 1: "y", 2: "z"}
    a = None
    if cut is not None and cut.type in ("revolute", "continuous", "prismatic", "cylindrical", "universal", "planar"):
        a = state.frame_placement(cut.frame1).rotation @ np.asarray(cut.axis, float)
        a = a / np.linalg.norm(a)
    if a is None:
        return np.eye(3)[0], np.eye(3)[1], np.eye(3)[2], ("x", "y", "z")
    k = int(np.argmax(np.abs(a)))
    if abs(abs(a[k]) - 1) <= tol.geometry:  # the axis is a world axis
        others = [i for i in range(3) if i != k]
        e1, e2 = np.eye(3)[others[0]], np.eye(3)[others[1]]
        return e1, e2, a, (letters[others[0]], letters[others[1]], f"the axis ({letters[k]})")
    e1, e2 = perpendicular_basis(a)
    return e1, e2, a, ("a direction across the axis", "the other direction across it", "the axis")


def _describe_span(W: np.ndarray | list, at: np.ndarray, dirs: tuple, L: float, tol: Tolerances) -> tuple[tuple, str]:
    """(named canonical wrenches, words) of the span of wrenches W (k, 6) at point ``at`` (moment
    about the world origin): canonical when the span is that of some of the joint's six canonical
    wrenches, else each basis wrench as a screw."""
    e1, e2, e3, labels = dirs
    # at the joint's point, forces times L so that forces and moments weigh alike
    Wp = np.array([np.r_[w[:3] * L, w[3:] - np.cross(at, w[:3])] for w in W])
    Q = np.linalg.svd(Wp, full_matrices=False)[2][:len(W)] if len(W) else np.zeros((0, 6))
    E = [np.r_[e, np.zeros(3)] for e in (e1, e2, e3)] + [np.r_[np.zeros(3), e] for e in (e1, e2, e3)]
    weight = [float(np.linalg.norm(Q @ e)) for e in E]
    inside = [k for k, w in enumerate(weight) if abs(w - 1) <= tol.geometry]
    if len(inside) == len(W) and all(abs(w - 1) <= tol.geometry or w <= tol.geometry for w in weight):
        names = [CANONICAL[k].format(None, *labels) for k in inside]
        forces = [n.replace("force along ", "") for n in names if n.startswith("force")]
        moments = [n.replace("moment about ", "") for n in names if n.startswith("moment")]
        parts = []
        if len(forces) == 3:
            parts.append("the force in every direction")
        elif forces:
            parts.append(f"the force{'s' if len(forces) > 1 else ''} along " + _and(forces))
        if len(moments) == 3:
            parts.append("the moment about every axis")
        elif moments:
            parts.append(f"the moment{'s' if len(moments) > 1 else ''} about " + _and(moments))
        return tuple(names), " and ".join(parts)
    words = []
    for w in W:
        s = screw_of(np.r_[w[3:], w[:3]])  # a wrench (f, m) read as the screw (m, f): axis along f
        if not np.isfinite(s.pitch):
            words.append("a couple about (" + ", ".join(f"{x:.3g}" for x in s.direction) + ")")
        else:
            through = "" if s.point is None else " through (" + ", ".join(f"{x:.4g}" for x in s.point) + ") m"
            pitch = "" if abs(s.pitch) <= tol.geometry * L else f" with a moment of pitch {s.pitch:.4g} m"
            words.append("a force along (" + ", ".join(f"{x:.3g}" for x in s.direction) + ")" + through + pitch)
    return (), "; ".join(words)


def _and(items: list) -> str:
    return items[0] if len(items) == 1 else ", ".join(items[:-1]) + " and " + items[-1]


def _algebra(mech: Mechanism, q: np.ndarray) -> tuple:
    """(kind, where, L): the algebra every tree screw lies in ("se(3)", "se(2)" with its normal, "so(3)"
    with its point; analysis.loop_series.subalgebra) and the characteristic length."""
    system = loop_system(mech, q, reduce=False)
    kind, where = subalgebra(system.screws[system.column < mech.nv], mech.tolerances.geometry)
    return kind, where, system.length


def _why(mech: Mechanism, W: np.ndarray | list, algebra: tuple) -> str:
    """Why a joint's redundant wrenches W (k, 6) are there: "planar" when every one does no work on the
    planar motions the tree's joints make (their screws all lie in one plane's se(2)), "spherical"
    likewise on the rotations about one point, "planar and overconstrained" when only some do, else
    "overconstrained" (the linkage's geometry keeps the rows dependent: Bennett, Sarrus, two frames
    fixing one centre distance)."""
    kind, where, L = algebra
    if kind == "se(3)" or not len(W):
        return "overconstrained"
    # a wrench (f, m) pairs with a dimensionless twist (v/L, w) as (f L) . (v/L) + m . w
    algebra = split(kind, where, np.eye(6))[0]
    Ws = np.hstack([W[:, :3] * L, W[:, 3:]])
    s = np.linalg.svd(Ws, compute_uv=False)
    inside = np.linalg.svd(Ws @ algebra.T, compute_uv=False) if len(W) else np.zeros(0)
    working = int(np.sum(inside > mech.tolerances.geometry * max(s[0], 1.0)))
    name = "planar" if kind == "se(2)" else "spherical"
    if working == 0:
        return name
    return f"{name} and overconstrained" if working < len(W) else "overconstrained"


def redundancy(mech: Mechanism, q: np.ndarray, suggest_fix: bool = False) -> Redundancy:
    """The redundant constraints of ``mech`` at the assembled configuration q; with ``suggest_fix`` the
    joints that make it exactly constrained, checked (see the module docstring)."""
    from scipy.linalg import qr

    Ks, Lam, labels = _left_null(mech, q)
    count = Lam.shape[1]
    qr_rows, qr_rank = (), 0
    if Ks.size:
        _, R, piv = qr(Ks.T, pivoting=True, mode="economic")
        diag = np.abs(np.diag(R))
        qr_rank = int(np.sum(diag > max(mech.tolerances.rank_rtol * (diag[0] if diag.size else 0.0),
                                        mech.tolerances.rank_atol)))
        qr_rows = tuple(labels[i] for i in sorted(piv[qr_rank:]))
    state = KinematicState(mech, q)
    wrench_rows = mech.closure.row_wrenches(q)
    # the joint each row belongs to; a higher pair's coupling row apart from its weld's rows
    owner = [lab.split(":", 1)[0] + (" (coupling)" if row[0] is None else "") for lab, row in zip(labels, wrench_rows)]
    basis, row_sets = [], []
    for k in range(count):
        lam = Lam[:, k]
        per = {}
        for i, (fa, _wa, fb, wb) in enumerate(wrench_rows):
            if abs(lam[i]) <= mech.tolerances.zero * np.abs(lam).max():
                continue
            if fa is None:  # a coupling row: its multiplier is what it carries
                per[owner[i]] = per.get(owner[i], 0.0) + lam[i]
                continue
            p = state.frame_placement(fb).translation
            w = wb * lam[i]
            per[owner[i]] = per.get(owner[i], np.zeros(6)) + np.r_[w[:3], w[3:] + np.cross(p, w[:3])]
        basis.append(per)
        row_sets.append({labels[i]: float(lam[i]) for i in range(len(labels))
                         if abs(lam[i]) > mech.tolerances.zero * np.abs(lam).max()})
    joints = _per_joint(mech, q, state, Lam, wrench_rows, owner) if count else ()
    found = suggest(mech, q, count) if suggest_fix and count else None
    return Redundancy(count, tuple({j: (tuple(map(float, w)) if isinstance(w, np.ndarray) else float(w))
                                    for j, w in b.items()} for b in basis), tuple(row_sets), joints, qr_rows,
                      qr_rank, found)


def _per_joint(mech: Mechanism, q: np.ndarray, state: KinematicState, Lam: np.ndarray, wrench_rows: list, owner: list) -> tuple:
    """JointRedundancy of every joint carrying part of the left null space."""
    algebra = _algebra(mech, q)
    out = []
    kinds = _cut_words(mech)
    cuts = {c.name: c for c in mech.cuts}
    L = mech.length
    for name in dict.fromkeys(owner):
        idx = [i for i, o in enumerate(owner) if o == name]
        part = Lam[idx]
        k = rank(part, mech.tolerances) if part.size else 0
        if not k:
            continue
        cut = cuts.get(name)
        if wrench_rows[idx[0]][0] is None:  # a coupling of coordinates (rolling, gear, screw: its law)
            coupling = wrench_rows[idx[0]][1]
            out.append(JointRedundancy(coupling.name, "coupling", len(idx), k, (), (), (), f"its {coupling.kind} law",
                                       "overconstrained"))
            continue
        fb = wrench_rows[idx[0]][2]
        p = state.frame_placement(fb).translation
        W = []
        for col in np.linalg.svd(part, full_matrices=False)[0][:, :k].T:  # an orthonormal basis of its part
            w = sum(wrench_rows[i][3] * c for i, c in zip(idx, col))
            W.append(np.r_[w[:3], w[3:] + np.cross(p, w[:3])])
        W = np.array(W)
        dirs = _directions(cut, state, mech.tolerances)
        named, words = _describe_span(W, p, dirs, L, mech.tolerances)
        if named:  # the canonical wrenches themselves, about the world origin
            W = _canonical_wrenches(named, dirs, p)
        why = _why(mech, W, algebra)
        out.append(JointRedundancy(name, kinds.get(name, "loop joint"), len(idx), k,
                                   tuple(tuple(map(float, w)) for w in W), tuple(map(float, p)), named,
                                   f"{k} of its {len(idx)} rows, " + words, why))
    return tuple(out)


def _canonical_wrenches(named: tuple, dirs: tuple, p: np.ndarray) -> np.ndarray:
    e1, e2, e3, labels = dirs
    out = []
    for n in named:
        k = next(i for i, c in enumerate(CANONICAL) if c.format(None, *labels) == n)
        e = (e1, e2, e3)[k % 3]
        out.append(np.r_[e, np.cross(p, e)] if k < 3 else np.r_[np.zeros(3), e])
    return np.array(out)


def _rotation_twist(u: np.ndarray, p: np.ndarray) -> np.ndarray:
    return np.r_[np.cross(p, u), u]


def _options(mech: Mechanism, state: KinematicState, name: str, kind: str, axis: np.ndarray | tuple, point: np.ndarray, axes: list) -> list:
    """(new type, [(world twist, words)], replacement) for each way to free more at one joint; ``axes``:
    the directions a universal joint's second axis may take ((world vector, letter or None))."""
    opts = []
    if kind == "revolute":
        e1, e2 = perpendicular_basis(axis)
        opts.append(("spherical", [_rotation_twist(e1, point), _rotation_twist(e2, point)], None))
        for u, letter in axes:
            opts.append(("universal", [_rotation_twist(u, point)], letter))
        opts.append(("cylindrical", [np.r_[axis, np.zeros(3)]], None))
    elif kind == "prismatic":
        opts.append(("cylindrical", [_rotation_twist(axis, point)], None))
    elif kind == "universal":
        opts.append(("spherical", [_rotation_twist(np.cross(axis[0], axis[1]), point)], None))
    return opts


def _candidates(mech: Mechanism, state: KinematicState) -> list:
    """The joints a suggestion may change, in the order it tries them: cut joints, then unactuated tree
    joints on the ground, then the other unactuated ones, then the actuated ones; each (name, is a cut,
    options)."""
    model = mech.model
    out = []
    for cut in mech.cuts:
        if cut.pair:
            continue
        M1 = state.frame_placement(cut.frame1)
        a = M1.rotation @ np.asarray(cut.axis, float)
        a = a / np.linalg.norm(a)
        if cut.type in ("revolute", "continuous"):
            e1, e2 = perpendicular_basis(a)
            out.append((cut.name, True, _options(mech, state, cut.name, "revolute", a, M1.translation,
                                                 [(e1, None), (e2, None)])))
        elif cut.type == "prismatic":
            out.append((cut.name, True, _options(mech, state, cut.name, "prismatic", a, M1.translation, [])))
        elif cut.type == "universal":
            a2 = state.frame_placement(cut.frame2).rotation @ np.asarray(cut.axis2, float)
            out.append((cut.name, True, _options(mech, state, cut.name, "universal", (a, a2 / np.linalg.norm(a2)),
                                                 M1.translation, [])))
    tree = []
    virtual = {n for names in mech.virtual_joints.values() for n in names}
    ground = {c.joint_id for c in mech.coordinates if model.parents[c.joint_id] == 0}
    for c in mech.coordinates:
        short = model.joints[c.joint_id].shortname()
        if c.nv != 1 or "JointModelR" not in short or c.joint in virtual:
            continue
        M = state.joint_placement(c.joint_id)
        local = joint_axis(model.joints[c.joint_id])
        a = M.rotation @ local
        axes = []
        k = int(np.argmax(np.abs(local)))
        if abs(abs(local[k]) - 1) <= mech.tolerances.geometry:  # the joint's axis is one of its frame's axes
            for i in range(3):
                if i != k:
                    axes.append((M.rotation[:, i], "XYZ"[k] + "XYZ"[i]))
        rank_key = (c.joint in mech.actuated, c.joint_id not in ground)
        tree.append((rank_key, (c.joint, False, _options(mech, state, c.joint, "revolute", a, M.translation, axes))))
    tree.sort(key=lambda t: t[0])
    # a tree joint becomes spherical or universal through the sidecar's replacements only
    return out + [(n, False, [o for o in opts if o[0] == "spherical" or (o[0] == "universal" and o[2])])
                  for _, (n, _, opts) in tree]


def _column(system: LoopSystem, mech: Mechanism, name: str, is_cut: bool, twist: np.ndarray) -> np.ndarray:
    """The column of A (unreduced loop system) that a new freedom ``twist`` (world) at joint ``name`` adds."""
    t = np.asarray(twist, float).copy()
    t[:3] /= system.length
    blocks = np.zeros((len(mech.cuts), 6))
    if is_cut:
        blocks[system.cut_names.index(name)] = -t
    else:
        iv = mech.coordinate(name).idx_v
        u = int(np.flatnonzero(system.column == iv)[0])
        blocks = system.sigma[:, u][:, None] * t[None, :]
    col = np.concatenate(list(blocks))
    return np.concatenate([col, np.zeros(system.rows - len(col))])


def suggest(mech: Mechanism, q: np.ndarray, count: int | None = None) -> Suggestion | None:
    """Joints that make the model exactly constrained (see the module docstring), checked by building it."""
    tol = mech.tolerances
    system = loop_system(mech, q, reduce=False)
    if not system.supported or system.contacts is not None:
        return None
    K = mech.closure.jacobian(q)
    d = mech.nv - rank(K, tol)
    A = system.jacobian
    U_A = np.linalg.svd(A)[0] if A.size else np.eye(A.shape[0])
    U = U_A[:, A.shape[1] - d:]
    c = U.shape[1] if count is None else count
    if not c:
        return None
    state = KinematicState(mech, q)
    chosen, cols = [], []

    def effective(columns) -> int:
        if not columns:
            return 0
        s = np.linalg.svd(U.T @ np.array(columns).T, compute_uv=False)
        return int(np.sum(s > tol.geometry))

    for name, is_cut, options in _candidates(mech, state):
        best = None
        for new_type, twists, letter in options:
            new = [_column(system, mech, name, is_cut, t) for t in twists]
            total = len(cols) + len(new)
            if total > c or effective(cols + new) != total:
                continue
            score = (len(new), float(np.linalg.svd(U.T @ np.array(cols + new).T, compute_uv=False)[-1]))
            if best is None or score > best[0]:
                best = (score, new_type, twists, letter, new)
        if best is not None:
            _, new_type, twists, letter, new = best
            chosen.append((name, is_cut, new_type, twists, letter))
            cols += new
        if len(cols) == c:
            break
    if len(cols) != c:
        return Suggestion((), "none found: no change of joints to spherical, universal or cylindrical ones (a tree "
                              "joint: spherical or universal, as a sidecar replaces it) releases every redundant "
                              "constraint" + (" (forces through the sphere's centre: only sliding joints release them)"
                                              if _algebra(mech, q)[0] == "so(3)" else ""), None, None, "not built")
    words = _change_words(mech, chosen)
    changes = tuple((n, t, w) for (n, _, t, _, _), w in zip(chosen, words))
    text = "make " + _and([w for w in words])
    M, over, checked = _check(mech, q, chosen)
    return Suggestion(changes, text, M, over, checked)


def _change_words(mech: Mechanism, chosen: list) -> list:
    kinds = _cut_words(mech)
    out = []
    for name, is_cut, new_type, twists, letter in chosen:
        who = f"{kinds[name]} '{name}'" if is_cut and kinds.get(name) in ("connect", "weld") else name
        extra = ""
        if new_type == "universal":
            u = twists[0][3:]
            extra = (f" (its second axis along its frame's {letter[1].lower()} axis)" if letter else
                     " (its second axis along (" + ", ".join(f"{x:.3g}" for x in u) + "))")
        out.append(f"{who} {new_type}{extra}")
    return out


def _check(mech: Mechanism, q: np.ndarray, chosen: list) -> tuple:
    """(mobility, overconstraint, words) of the mechanism with the chosen joints, built and analysed:
    the largest rank of K over its generic configurations."""
    spec = copy.deepcopy(mech.spec)
    state = KinematicState(mech, q)
    cuts = {c.name: c for c in mech.cuts}
    for name, is_cut, new_type, twists, letter in chosen:
        if not is_cut:
            spec.replacements = [r for r in spec.replacements if r[0] != name]
            spec.replacements.append((name, "SPHERICAL" if new_type == "spherical" else f"UJOINT_{letter}"))
            continue
        k = next(i for i, c in enumerate(spec.cut_joints) if c.name == name)
        axis2 = None
        if new_type == "universal":
            R2 = state.frame_placement(cuts[name].frame2).rotation
            axis2 = tuple(float(x) for x in R2.T @ twists[0][3:])
        spec.cut_joints[k] = replace(spec.cut_joints[k], type=new_type, axis2=axis2)
    try:
        other = rebuild(spec, actuated=list(mech.actuated), tolerances=mech.tolerances)
        configs = other.generic_configurations()[1]
        r = max(rank(other.closure.jacobian(x), other.tolerances) for x in configs)
    except ScrewkinError as exc:
        return None, None, f"the changed model could not be analysed: {exc}"
    over = other.closure.nrows - r
    return other.nv - r, over, (f"built and analysed: {other.nv} coordinates, {other.closure.nrows} constraint rows, "
                                f"rank {r} over {len(configs)} assembled configurations")
