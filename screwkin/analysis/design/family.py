"""A study's family on its fast path: a xacro family whose structure does not change with its
parameters, expanded once for a chunk of designs and its planar four-bars analysed in closed form
over all of them at once.

For a chunk of designs (chunk_rows, what a Dask task runs):

1. the xacro file is expanded once with the parameters as arrays (files.xacro_batch.read_designs); each design's
   URDF is that template with its numbers, read and checked as any file is (files.urdf.read_urdf:
   the same problems refuse it); a design whose expansion or file fails, or whose structure (links,
   joints, loop joints, their types and links, which links are massless) differs from the others,
   is evaluated alone;
2. one design (the reference) is evaluated alone, as every design was before: loaded, assembled,
   its metrics computed -- its row is that evaluation's.  Its mechanism says which joints make the
   four-bar (analysis.motion.planar.identify) and which sides its loop has
   (model.closability.planar_loops);
3. every other design's joint centres and loop frames are placed by composing its file's origins
   along the tree (numpy, all designs at once; for the reference they must be Pinocchio's to 1e-9
   of its size), and from them its link lengths in the plane of motion: the Grashof class and margin
   and the transmission angle's located extremes are analysis.motion.transmission's closed forms on
   those arrays; the mobility columns are the reference's (a planar 4R loop that closes with link
   lengths of one order, all axes parallel: M = 1 and the same counts);
4. a loop whose lengths cannot close is the failed row the single commands give (the same sentence,
   proved from the lengths: model.closability); a loop within the tolerance of closing or not, a
   link three orders shorter than the longest, axes that are not parallel: evaluated alone;
5. one more design, drawn at random (seeded by the chunk), is evaluated alone and must give the
   family path's row to 1e-9; if not, the whole chunk is evaluated design by design (said in the
   notes).

Rows come back in design order, with which path each design took (``ChunkRows.paths``) and why
designs were evaluated alone (``ChunkRows.notes``).
"""

from __future__ import annotations

import math
import warnings
from collections import Counter
from typing import TYPE_CHECKING

import numpy as np

from ...errors import AssemblyError, UsageError
from ...files.xacro import is_xacro
from ...files.xacro_batch import Unbatchable, read_designs
from ...model.closability import obstacle_of, planar_loops
from ...model.state import KinematicState
from ..motion.transmission import FOUR_BAR_CLASSES, four_bar_classes, four_bar_transmission
from .study import (COLUMNS, StudyDesign, StudyTask, evaluate_design, failed_row, failure_reason, grashof_short,
                    metric_columns, run_chunk)

if TYPE_CHECKING:
    from ...files.description import MechanismSpec
    from ...tolerances import Tolerances
    from collections.abc import Sequence

__all__ = ["ChunkRows", "FAMILY_CHUNK", "FAMILY_METRICS", "chunk_rows", "eligible", "family_rows"]

#: The metrics the family path computes over designs at once.
FAMILY_METRICS = ("mobility", "grashof", "transmission_angle")
#: Most designs in one chunk of the family path (about 1 s of work; the progress bar moves a chunk at a time).
FAMILY_CHUNK = 1000
#: A link shorter than this fraction of the longest: the design is evaluated alone (ranks near round-off).
SHORT_LINK = 1e-3
#: Rows of the family path and of the design's own evaluation agree to this (relative, 1 below 1).
AGREE = 1e-9


class ChunkRows(list):
    """A chunk's rows, with ``paths`` ({"family": n, "design": m}) and ``notes`` (why designs were
    evaluated alone), sent back with them from the worker."""

    def __init__(self, rows=(), paths=None, notes: tuple=()) -> None:
        super().__init__(rows)
        self.paths = dict(paths or {})
        self.notes = list(notes)


def eligible(task: StudyTask) -> str | None:
    """Why the family path does not apply to a study (None: it may)."""
    other = [m for m in task.metrics if m not in FAMILY_METRICS]
    if other:
        return f"the metric {other[0]} has no closed form over designs"
    if not task.parameters or not is_xacro(task.file, task.text):
        return "the family is not a xacro file with parameters"
    return None


def chunk_rows(task, chunk: int) -> ChunkRows:
    """The rows of a chunk of designs [(index, values), ...]: what one Dask task computes.  A family
    whose structure does not change with its parameters takes the family path (family_rows); other
    studies, and the designs the family path cannot vouch for, are evaluated one by one
    (study.run_chunk).  The list says which path each design took (``paths``, ``notes``)."""
    with np.errstate(all="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        rows = family_rows(task, chunk)
    if rows is not None:
        return rows
    return ChunkRows(run_chunk(task, chunk), {"design": len(chunk)})


def _rpy_matrices(rpy: np.ndarray) -> np.ndarray:
    """Rotation matrices (n, 3, 3) of URDF rpy angles (n, 3): Rz(yaw) Ry(pitch) Rx(roll)."""
    r, p, y = rpy[:, 0], rpy[:, 1], rpy[:, 2]
    cr, sr, cp, sp, cy, sy = np.cos(r), np.sin(r), np.cos(p), np.sin(p), np.cos(y), np.sin(y)
    return np.stack([np.stack([cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr], -1),
                     np.stack([sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr], -1),
                     np.stack([-sp, cp * sr, cp * cr], -1)], -2)


def _signature(spec: MechanismSpec, dummy_mass: float) -> tuple:
    """What must be the same for two designs to share a structure."""
    return (tuple((k, v.is_massless(dummy_mass), v.has_geometry) for k, v in spec.links.items()),
            tuple((j.name, j.type, j.parent, j.child, j.mimic) for j in spec.joints),
            tuple((c.name, c.type, c.frame1, c.frame2, c.source, c.axis2 is None, c.radius1, c.radius2, c.contact,
                   c.profile1, c.profile2, c.lead) for c in spec.cut_joints),
            tuple(spec.transmissions), tuple(spec.couplings), tuple(spec.replacements), spec.yaml_path)


class _Placed:
    """Every design's tree joint frames and loop-joint frames at the file's configuration (all joints
    at zero), composed from their files' origins: world (R (n, 3, 3), p (n, 3))."""

    def __init__(self, specs) -> None:
        first = specs[0]
        n = len(specs)
        links = {first.root: (np.broadcast_to(np.eye(3), (n, 3, 3)), np.zeros((n, 3)))}
        self.joints, self.axes = {}, {}
        pending = list(range(len(first.joints)))
        while pending:
            left = []
            for k in pending:
                j = first.joints[k]
                if j.parent not in links:
                    left.append(k)
                    continue
                R0, p0 = links[j.parent]
                xyz = np.array([s.joints[k].xyz for s in specs], float)
                rpy = np.array([s.joints[k].rpy for s in specs], float)
                axis = np.array([s.joints[k].axis for s in specs], float)
                R = R0 @ _rpy_matrices(rpy)
                p = p0 + np.einsum("nij,nj->ni", R0, xyz)
                links[j.child] = (R, p)
                self.joints[j.name] = (R, p)
                self.axes[j.name] = np.einsum("nij,nj->ni", R, axis)
            if len(left) == len(pending):
                raise Unbatchable("the tree of joints does not reach every link from the root")
            pending = left
        self.cuts = {}
        for k, c in enumerate(first.cut_joints):
            frames = []
            for link, xyz_of, rpy_of in ((c.frame1, "xyz1", "rpy1"), (c.frame2, "xyz2", "rpy2")):
                if link not in links:
                    raise Unbatchable(f"loop joint {c.name} names a frame that is not a link")
                R0, p0 = links[link]
                xyz = np.array([getattr(s.cut_joints[k], xyz_of) for s in specs], float)
                rpy = np.array([getattr(s.cut_joints[k], rpy_of) for s in specs], float)
                frames.append((R0 @ _rpy_matrices(rpy), p0 + np.einsum("nij,nj->ni", R0, xyz)))
            self.cuts[c.name] = frames
            axis = np.array([s.cut_joints[k].axis for s in specs], float)
            self.axes[c.name] = np.einsum("nij,nj->ni", frames[0][0], axis / np.linalg.norm(axis, axis=1)[:, None])


def _equal(a: object, b: object) -> bool:
    if isinstance(a, float) and isinstance(b, float):
        return abs(a - b) <= AGREE * max(1.0, abs(a), abs(b))
    return a == b and type(a) is type(b)


def _differs(row: dict, other: dict, columns: Sequence[str]):
    for c in ("error", *columns):
        if not _equal(row[c], other[c]):
            return c
    return None


class _Fourbar:
    """The reference design's four-bar: which joint centres and loop frames each link's length joins,
    and the sides of its loop (model.closability.planar_loops)."""

    def __init__(self, d: StudyDesign, spec) -> None:
        mech, info = d.mech, d.linkage()
        if info.kind != "four-bar":
            raise Unbatchable("the family path analyses four-bars (this one is a slider-crank)")
        topo = mech.topology(d.q)
        cuts = {c.name: c for c in spec.cut_joints}
        joints = {j.name: j for j in topo.joints}
        inp = joints[info.input_joint]
        ground = topo.ground

        def other(link: str, joint):
            return next(j for j in topo.joints if j is not joint and link in j.links)

        def far(joint, link: str):
            return joint.links[1] if joint.links[0] == link else joint.links[0]

        moving = far(inp, ground)
        j_b = other(moving, inp)
        coupler = far(j_b, moving)
        j_c = other(coupler, j_b)
        output = far(j_c, coupler)
        j_d = other(ground, inp)
        self.input, self.input_name = inp.name, info.input_joint
        self.sides = {}  # length name -> ((joint, link), (joint, link))
        for name, link, (ja, jb) in (("ground", ground, (inp, j_d)), ("input", moving, (inp, j_b)),
                                     ("coupler", coupler, (j_b, j_c)), ("output", output, (j_c, j_d))):
            for j in (ja, jb):
                if len(j.members) != 1 and j.name not in cuts:
                    raise Unbatchable(f"joint {j.name} is a compound joint")
            self.sides[name] = ((ja.name, link), (jb.name, link))
        self.cut_names = cuts
        self.loops = [(cut, names, points) for cut, names, points, _ in planar_loops(mech)]
        self.names = {k: mech.model.names[k] for k in range(1, mech.model.njoints)}
        self.frames = {}
        for c in mech.cuts:
            self.frames[c.frame1] = (c.name, 0)
            self.frames[c.frame2] = (c.name, 1)
        self.lengths = info.lengths

    def point(self, placed: _Placed, joint, link: str):
        """The joint's centre (a loop joint: its frame on ``link``) at every design: (n, 3)."""
        if joint in self.cut_names:
            c = self.cut_names[joint]
            side = 0 if c.frame1 == link else 1 if c.frame2 == link else None
            if side is None:
                raise Unbatchable(f"loop joint {joint} is not on link {link}")
            return placed.cuts[joint][side][1]
        return placed.joints[joint][1]

    def ref_point(self, placed: _Placed, ref):
        kind, ident = ref
        if kind == "frame":
            name, side = self.frames[ident]
            return placed.cuts[name][side][1]
        return placed.joints[self.names[ident]][1]


def _flat(P: np.ndarray, n: int):
    return P - np.einsum("ni,ni->n", P, n)[:, None] * n


def family_rows(task: StudyTask, chunk: list[tuple[int, tuple]]) -> ChunkRows | None:
    """The rows of ``chunk`` ([(index, values), ...]) by the family path (module docstring), a
    ChunkRows; None when the study is not one it applies to (its metrics, a plain file)."""
    if eligible(task) is not None:
        return None
    index = [i for i, _ in chunk]
    values = np.array([v for _, v in chunk], float)
    try:
        return _family(task, chunk, index, values)
    except Unbatchable as exc:
        rows = [evaluate_design(task, i, v) for i, v in chunk]
        return ChunkRows(rows, {"design": len(chunk)}, [f"designs {index[0]}-{index[-1]} evaluated one by one: "
                                                        f"{exc}"])


def _reference(task: StudyTask, chunk: list[tuple[int, tuple]], index: list[int], specs: list,
               alone: dict[int, str]) -> tuple[list[dict | None], int, StudyDesign]:
    """(the rows evaluated alone so far, the reference's position, the reference design): the reference is the
    first design whose own evaluation analyses it."""
    rows: list[dict | None] = [None] * len(chunk)
    for k in range(len(chunk)):
        if specs[k] is None:
            continue
        kept: list[StudyDesign] = []
        rows[k] = evaluate_design(task, index[k], chunk[k][1], keep=kept)
        if kept:
            return rows, k, kept[0]
        alone[k] = "its own evaluation fails (its row says why)"
        if sum(1 for r in rows if r is not None) >= 3:
            raise Unbatchable("three designs in a row could not be analysed alone")
    raise Unbatchable("no design of the chunk could be analysed")


def _same_structure(specs: list, ref: int, dummy: float, alone: dict[int, str]) -> list[int]:
    """The designs besides the reference that share its structure (the others: in ``alone``, with why)."""
    sig = _signature(specs[ref], dummy)
    fast = [k for k in range(len(specs)) if specs[k] is not None and k not in alone and k != ref]
    for k in fast:
        if _signature(specs[k], dummy) != sig:
            alone[k] = "its structure differs (links, joints, their types or massless links)"
    return [k for k in fast if k not in alone]


class _ClosedForms:
    """The four-bar's closed forms at every member design (the reference first): whether its axes are parallel
    (``planar``), its link lengths in the plane of motion, the loops proved not to close (``proved``: position ->
    (reason, gap)), which designs the closed forms vouch for (``ok``), the Grashof class codes and margins and
    the transmission angle's extremes."""

    def __init__(self, fb: _Fourbar, placed: _Placed, spec: MechanismSpec, tol: Tolerances, members: int) -> None:
        n_in = placed.axes[fb.input_name]
        n_in = n_in / np.linalg.norm(n_in, axis=1)[:, None]
        planar = np.ones(members, bool)
        for name, a in placed.axes.items():
            kind = next((j.type for j in spec.joints if j.name == name), None) or \
                next(c.type for c in spec.cut_joints if c.name == name)
            if kind in ("revolute", "continuous"):
                planar &= np.linalg.norm(np.cross(a / np.linalg.norm(a, axis=1)[:, None], n_in), axis=1) <= tol.geometry
        L = {}
        for name, ((ja, la), (jb, lb)) in fb.sides.items():
            L[name] = np.linalg.norm(_flat(fb.point(placed, ja, la), n_in) - _flat(fb.point(placed, jb, lb), n_in),
                                     axis=1)
        g, a, b, c = L["ground"], L["input"], L["coupler"], L["output"]
        longest = np.maximum.reduce([g, a, b, c])
        size = np.maximum(longest, 1.0)
        # the loop's sides as model.closability measures them, and whether it closes
        self.proved: dict[int, tuple[str, float]] = {}
        margin_ok = np.ones(members, bool)
        for cut, names, points in fb.loops:
            P = [_flat(fb.ref_point(placed, r), n_in) for r in points]
            sides = np.stack([np.linalg.norm(P[k + 1] - P[k], axis=1) for k in range(len(P) - 1)], axis=1)
            excess = sides.max(axis=1) - (sides.sum(axis=1) - sides.max(axis=1))
            margin_ok &= np.abs(excess - tol.geometry) > tol.equal * size  # clear of the test's own threshold
            for m in np.flatnonzero(excess > tol.geometry):
                if int(m) not in self.proved:
                    self.proved[int(m)] = obstacle_of(cut, names, list(map(float, sides[m])), tol.geometry)
        closes = -(np.maximum.reduce([g, a, b, c]) - (g + a + b + c - longest))  # others - longest
        ok = planar & margin_ok & (np.minimum.reduce([g, a, b, c]) > SHORT_LINK * longest)
        ok &= (closes > tol.equal * size) | np.isin(np.arange(members), list(self.proved))
        self.planar, self.ok = planar, ok
        self.codes = four_bar_classes(g, a, b, c, tol.equal)
        self.mu_lo, self.mu_hi, self.turns, self.dead = four_bar_transmission(g, a, b, c, tol.equal)
        srt = np.sort(np.stack([g, a, b, c]), axis=0)
        self.margin = srt[1] + srt[2] - srt[0] - srt[3]

    def row(self, m: int, task: StudyTask, i: int, values: tuple, reference: dict) -> dict:
        """The family path's row of member ``m`` (design ``i`` of ``values``)."""
        return _row_of(task, i, values, metric_columns(task.metrics), reference, self.codes[m], self.margin[m],
                       self.mu_lo[m], self.mu_hi[m], self.turns[m], self.dead[m])


def _made_rows(task: StudyTask, chunk: list[tuple[int, tuple]], index: list[int], members: list[int], ref: int,
               reference: dict, cf: _ClosedForms, alone: dict[int, str]) -> dict[int, dict]:
    """The rows the closed forms give (position -> row), the reference's not yet; the designs they cannot vouch
    for in ``alone``, with why."""
    made = {}
    for m, k in enumerate(members):
        if k == ref:
            continue
        if not cf.ok[m]:
            alone[k] = ("its axes are not parallel" if not cf.planar[m] else
                        "its loop is within the tolerance of closing or not, or a link is nearly zero")
            continue
        if m in cf.proved:  # the failed row of a loop that cannot close: the single commands' sentence
            reason, gap = cf.proved[m]
            made[k] = failed_row(task, index[k], chunk[k][1], failure_reason(
                AssemblyError(task.file, gap, 0, starts=0, reason=reason, proved=True), task.file))
        else:
            made[k] = cf.row(m, task, index[k], chunk[k][1], reference)
    return made


def _vouch(task: StudyTask, chunk: list[tuple[int, tuple]], index: list[int], ref: int, reference: dict,
           cf: _ClosedForms, made: dict[int, dict]) -> None:
    """The family path's rows must be the designs' own: the reference's recomputed, and one drawn at random
    (Unbatchable when one differs).  Every design the family path covers reports its closed-form row (the
    reference and the drawn one too), so that a design's row does not depend on which chunk it fell in."""
    columns = metric_columns(task.metrics)
    if reference["error"] is None and cf.ok[0]:
        mine = cf.row(0, task, index[ref], chunk[ref][1], reference)
        col = _differs(mine, reference, columns)
        if col is not None:
            raise Unbatchable(f"the closed form's {col} of design {index[ref]} ({mine[col]!r}) is not its own "
                              f"evaluation's ({reference[col]!r})")
        made[ref] = mine
    candidates = sorted(k for k in made if k != ref)
    if candidates:
        rng = np.random.default_rng(index[0])
        k = candidates[int(rng.integers(len(candidates)))]
        own = evaluate_design(task, index[k], chunk[k][1])
        col = _differs(made[k], own, columns)
        if col is not None:
            raise Unbatchable(f"the family path's {col} of design {index[k]} ({made[k][col]!r}) is not its own "
                              f"evaluation's ({own[col]!r})")


def _family(task: StudyTask, chunk: list[tuple[int, tuple]], index: list[int], values: np.ndarray) -> ChunkRows:
    n = len(chunk)
    specs, alone = read_designs(task.file, task.text, task.args,
                                {p: values[:, k] for k, p in enumerate(task.parameters)})
    rows, ref, d = _reference(task, chunk, index, specs, alone)
    spec, reference = specs[ref], rows[ref]
    assert spec is not None and reference is not None  # the reference's file was read and its row evaluated
    members = [ref] + _same_structure(specs, ref, d.mech.tolerances.dummy_mass, alone)
    try:
        fb = _Fourbar(d, spec)
    except UsageError as exc:  # not a four-bar (its own evaluation says so when it computes grashof)
        raise Unbatchable(str(exc)) from None
    placed = _Placed([specs[k] for k in members])
    _check_reference(d, fb, placed, spec)
    cf = _ClosedForms(fb, placed, spec, d.mech.tolerances, len(members))
    made = _made_rows(task, chunk, index, members, ref, reference, cf, alone)
    _vouch(task, chunk, index, ref, reference, cf, made)
    out: list[dict] = []
    reasons: Counter[str] = Counter()
    for k in range(n):
        if k in made:
            out.append(made[k])
            continue
        row = rows[k]
        if row is None:
            row = rows[k] = evaluate_design(task, index[k], chunk[k][1])
        out.append(row)
        reasons[alone.get(k, "the reference")] += 1
    notes = [f"{c} design{'s' if c != 1 else ''} evaluated alone: {why}" for why, c in reasons.most_common()]
    return ChunkRows(out, {"family": len(made), "design": n - len(made)}, notes)


def _row_of(task: StudyTask, i: int, values: tuple, columns: tuple[str, ...], reference: dict, code: int, margin: float,
            lo: float, hi: float, turns: bool, dead: int) -> dict:
    """The family path's row of one design from its closed-form numbers (the reference's recomputed)."""
    row = {"design": i, **dict(zip(task.parameters, values))}
    row.update(dict.fromkeys(columns))
    row["error"] = None
    if "mobility" in task.metrics:
        row.update({col: reference[col] for col in COLUMNS["mobility"]})
    if "grashof" in task.metrics:
        row.update({"linkage": "four-bar", "grashof": grashof_short(FOUR_BAR_CLASSES[int(code)]),
                    "grashof_margin": float(margin)})
    if "transmission_angle" in task.metrics:
        lo, hi = float(lo), float(hi)
        row.update({"transmission_angle_min": lo, "transmission_angle_max": hi, "transmission_restarts": 0,
                    "transmission_deviation": float(max(math.pi / 2 - lo, hi - math.pi / 2)),
                    "input_turns": bool(turns), "dead_points": int(dead)})
    return row


def _check_reference(d, fb: _Fourbar, placed: _Placed, spec) -> None:
    """The composed placements of the reference design (the first of ``placed``) are Pinocchio's at the
    file's configuration, to 1e-9 of the mechanism's size: the template and its reading are right."""
    mech = d.mech
    state = KinematicState(mech, mech.neutral())
    equal = mech.tolerances.equal
    scale = equal * max(mech.length, 1.0)
    for k in range(1, mech.model.njoints):
        name = mech.model.names[k]
        if name in placed.joints:
            R, p = placed.joints[name]
            M = state.joint_placement(k)
            if np.abs(p[0] - M.translation).max() > scale or np.abs(R[0] - M.rotation).max() > equal:
                raise Unbatchable(f"the family's template does not place joint {name} where its file does")
    for c in mech.cuts:
        for fid, (_R, p) in zip((c.frame1, c.frame2), placed.cuts[c.name]):
            if np.abs(p[0] - state.frame_placement(fid).translation).max() > scale:
                raise Unbatchable(f"the family's template does not place loop joint {c.name} where its file does")
