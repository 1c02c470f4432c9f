"""The serial singular curves of a chain's output point in a section of its workspace, and whether the
robot is cuspidal (issue 44).

For a chain without loops whose output point is moved by three joints (the others held), the section is
the plane of two of the point's coordinates with the third held (for a 3R whose first axis is z: y = 0, the
plane through that axis).  Its serial singular curve is traced like the loci in the plane of two inputs
(analysis.singularities.loci: the augmented system [held coordinate; held joints; J_p v = 0; |v| = 1],
J_p the point's Jacobian over the three free joints, dimensionless), seeded by Newton from random joint
configurations.  A cusp of that curve, where three inverse-kinematic solutions meet, makes a generic 3R
robot cuspidal -- it can change solution without a singularity -- and its absence makes it not
(Salunkhe, Spartalis, Capco, Chablat & Wenger 2022; for orthogonal robots Baili, Wenger & Chablat 2004);
a non-generic one (det J factoring) is decided by its aspects, and the verdict is None where nothing
establishes it (analysis.singularities.cuspidal).  The regions the curves cut the box into are counted by
the closed-form inverse kinematics at their samples.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, replace

import numpy as np
import pinocchio as pin

from ...errors import UsageError
from ...model.state import KinematicState
from .loci import Loci, LocusSystem, cusps_checked, trace_kind
from .loci_witness import unmatched
from .section_witness import section_witnesses
from .cuspidal import arm3r, aspects, point_ik, section_extent, verdict
from .regions import Regions, regions
from ..singular import LWA
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism

__all__ = ["Section", "SectionSystem", "trace_section"]

AXES = {"x": 0, "y": 1, "z": 2}


class SectionSystem(LocusSystem):
    """The augmented system of the serial singularity of ``output``'s origin in a workspace section."""

    def __init__(self, mech: Mechanism, output: str, x_axis: str, y_axis: str, level: float, fixed: dict | None) -> None:  # (LocusSystem's own set-up is for inputs)
        self.mech, self.kind, self.output, self.point = mech, "serial", output, True
        self.L = mech.length
        self.scale = np.where(mech.translational, self.L, 1.0)
        self.held = [(mech.coordinate(n), float(v), n) for n, v in fixed.items()]
        self.nv = mech.nv
        self.axes = (x_axis, y_axis)
        self.h = ({0, 1, 2} - {x_axis, y_axis}).pop()
        self.level = float(level)
        self.fid = mech.link_frame(output)
        held_v = {c.idx_v for c, _, _ in self.held}
        self.free = np.array([k for k in range(mech.nv) if k not in held_v], int)
        if len(self.free) != 3:
            raise UsageError(f"{mech.path}: a workspace section needs the point moved by three joints: "
                             f"{len(self.free)} are free (hold the others with --set)")
        names = list(mech.joint_values(mech.neutral()))
        self.angular = np.array([n in mech.coordinate_names and not mech.translational[mech.coordinate_names.index(n)]
                                 for n in names], bool)

    def _pose(self, q: np.ndarray) -> tuple:
        st = KinematicState(self.mech, q)
        J = st.frame_jacobian(self.fid, LWA)[:3] * self.scale / self.L  # d(p / L)/du
        return st.frame_placement(self.fid).translation.copy(), J

    def xy(self, q: np.ndarray) -> np.ndarray:
        p, _ = self._pose(q)
        return np.array([p[self.axes[0]], p[self.axes[1]]])

    def A(self, q: np.ndarray) -> np.ndarray:
        return self._pose(q)[1][:, self.free]

    def residual(self, q: np.ndarray, v: np.ndarray, A: np.ndarray | None=None) -> np.ndarray:
        p, J = self._pose(q)
        A = J[:, self.free] if A is None else A
        held = []
        for c, target, _ in self.held:
            d = self.value(q, c) - target
            held.append(np.arctan2(np.sin(d), np.cos(d)) if not self.mech.translational[c.idx_v] else d / self.L)
        return np.concatenate([[(p[self.h] - self.level) / self.L], held, A @ v, [0.5 * (v @ v - 1.0)]])

    def jacobian(self, q: np.ndarray, v: np.ndarray, A: np.ndarray | None=None) -> np.ndarray:
        _, J = self._pose(q)
        A = J[:, self.free] if A is None else A
        rows = [np.concatenate([J[self.h], np.zeros(len(v))])[None]]
        return np.vstack(rows + self._held_kind_norm_rows(q, v, A))

    def projected(self, q: np.ndarray, t: np.ndarray) -> np.ndarray:
        _, J = self._pose(q)
        return self.L * (J[list(self.axes)] @ t[:self.nv])

    def edge(self, axis: int, bound: float):
        def row(qc: np.ndarray, vc: np.ndarray) -> tuple:
            p, J = self._pose(qc)
            return (np.concatenate([J[self.axes[axis]], np.zeros(len(vc))])[None],
                    np.array([(bound - p[self.axes[axis]]) / self.L]))

        return row


def _overlapping(p: np.ndarray, curves: list, span: float, near: float) -> bool:
    """Whether the curves run together at p (one curve of the plane traced twice, by two curves or two passes
    of one) rather than cross there (a curve through p: within ``near`` of the span): the directions from p of the points at 0.25 to 1 % of the box's span of the
    curves through p fall in at most two bundles 10 deg apart (a crossing gives four)."""
    R = 0.01 * span

    def through(P: np.ndarray) -> bool:
        if len(P) < 2:
            return False
        A, d = P[:-1], np.diff(P, axis=0)
        t = np.clip(((p - A) * d).sum(axis=1) / np.maximum((d * d).sum(axis=1), 1e-300), 0.0, 1.0)
        return float(np.linalg.norm(A + t[:, None] * d - p, axis=1).min()) < near * span

    def dense(P: np.ndarray) -> np.ndarray:  # the polyline with points at most R / 8 apart
        d = np.diff(P, axis=0)
        k = np.maximum(1, np.ceil(np.linalg.norm(d, axis=1) / (R / 8))).astype(int)
        return np.vstack([P[i] + np.outer(np.arange(k[i]) / k[i], d[i]) for i in range(len(d))] + [P[-1:]])

    X = np.vstack([dense(P) for P in curves if through(P)] or [np.zeros((0, 2))])
    r = np.linalg.norm(X - p, axis=1)
    X = X[(r > R / 4) & (r < R)]
    if len(X) < 2:
        return False
    ang = np.sort(np.arctan2(X[:, 1] - p[1], X[:, 0] - p[0]))
    gaps = np.diff(np.concatenate([ang, ang[:1] + 2 * np.pi]))
    return int((gaps > np.radians(10.0)).sum()) <= 2


def _proved(proof, loci: list, cusps: list, box: tuple, notes: list) -> tuple:
    """(complete, cusps complete, the sentence) the witnesses (section_witness) prove of the traced curves."""
    if proof is None:
        return False, False, ". A component no random configuration converges to is missed, so completeness is not claimed"
    left = unmatched(proof, loci) if proof.certified else []
    if not proof.certified or left:
        if left:
            notes.append(f"serial: {len(left)} witness point(s) of the certificate lie on no traced curve, at "
                         + ", ".join(f"({w.xy[0]:.6g}, {w.xy[1]:.6g})" for w in left[:4]))
        return False, False, (". A component no seed converges to is missed, so completeness is not claimed ("
                              + proof.how + (f"; {len(left)} of them on no traced curve" if left else "") + ")")
    said, cusps_complete = cusps_checked(proof, cusps, box, notes, "serial")
    return True, cusps_complete, (f". Complete: {proof.how}; each of the {len(proof.points)} witnesses lies on a traced "
                                  "curve (a point of it in a box about the witness where the curve is one arc "
                                  "through it, or the curve's end on that bound)" + said)


@dataclass(frozen=True)
class Section:
    loci: Loci
    cuspidal: bool | None  # None: not established (why says so)
    why: str  # what the verdict rests on
    regions: Regions | None = None  # the box's regions, each with its number of real IK solutions
    generic: bool | None = None  # det J's zero set in joint space has no singular point
    aspects: int = 0  # connected parts of det J != 0 on the (t2, t3) torus
    extent: tuple | None = None  # the workspace section's (xmin, xmax, ymin, ymax) [m], where known


def trace_section(mech: Mechanism, output: str, x_axis: str, xs: np.ndarray, y_axis: str, ys: np.ndarray, level: float = 0.0, fixed: dict | None=None,
                  samples: int = 400, seed: int = 0, count: bool = True, certify: bool = True) -> Section:
    """The serial singular curves of ``output``'s origin in the section (x_axis, y_axis) of its workspace, the
    third coordinate held at ``level`` [m] and the joints in ``fixed`` at their values; cusps, nodes, the
    regions they cut the box xs x ys into with their numbers of real IK solutions (``count``), and whether
    the robot is cuspidal (analysis.singularities.cuspidal: True, False or None with the reason).  ``certify``:
    for three revolutes, prove the trace complete and its cusps all (section_witness; ik --connect, which uses
    the cusps only, leaves it)."""

    fixed = dict(fixed or {})
    if mech.cuts or mech.couplings or getattr(mech, "extra_rows", None):
        raise UsageError(f"{mech.path}: a workspace section is a serial chain's; this mechanism has loops, couplings "
                         "or contacts (map it over its inputs instead)")
    sys = SectionSystem(mech, output, AXES[x_axis], AXES[y_axis], level, fixed)
    box = ((min(xs[0], xs[-1]), max(xs[0], xs[-1])), (min(ys[0], ys[-1]), max(ys[0], ys[-1])))
    rng = np.random.default_rng(seed)
    starts = []
    for _ in range(samples):
        q = mech.random_configuration(rng)
        for c, v, _ in sys.held:
            q[c.idx_q] = v
        starts.append((sys.relative(q), q))
    starts.sort(key=lambda s: s[0])
    notes = []
    q0 = mech.neutral()
    for c, v, _ in sys.held:
        q0[c.idx_q] = v
    arm, why_not = arm3r(mech, sys.fid, sys.free, q0)
    ax = (AXES[x_axis], AXES[y_axis])
    proof = section_witnesses(arm, ax, sys.h, level, box) if arm is not None and certify else None
    seeds = itertools.chain((q for _, q in starts), (w.q for w in proof.points) if proof is not None else ())
    loci, cusps, cusp_q, nodes = trace_kind(sys, "serial", seeds, box, notes)
    span = max(box[0][1] - box[0][0], box[1][1] - box[1][0])
    kept = [n for n in nodes if not _overlapping(np.array(n[0]), [lc.points for lc in loci], span, mech.tolerances.singular)]
    if len(kept) < len(nodes):
        notes.append(f"{len(nodes) - len(kept)} meetings of traces that run together (one curve of the plane traced "
                     "twice, as where det J factors, or a closed trace's overlap at its start) are not nodes")
    nodes = kept
    complete, cusps_complete, said = _proved(proof, loci, cusps, box, notes)
    how = (f"seeds: Newton on [held coordinate; J_p v = 0; |v| = 1] from {samples} random joint configurations "
           "(seed {seed}), most singular first, then (for three revolutes) from the certificate's witness points; "
           "every curve followed by pseudo-arclength continuation to the box's edges or round to its start; cusps "
           "located by Brent's method where the trace reverses") + said
    result = Loci(tuple(loci), tuple(cusps), tuple(nodes), complete, how.replace("{seed}", str(seed)),
                  tuple(dict.fromkeys(notes)), tuple(cusp_q), ("serial",), cusps_complete)

    def world(p) -> np.ndarray:
        c = np.zeros(3)
        c[ax[0]], c[ax[1]], c[sys.h] = p[0], p[1], level
        return c

    def counter(p) -> tuple:
        sols, why = point_ik(arm, world(p))
        if why:
            return None, False, f"not counted: {why}"
        return len(sols), True, "closed form: the real roots of the position quartic (Pieper's first stage)"

    cut = regions(None, result, x_axis, xs, y_axis, ys, {}, count=count and arm is not None, counter=counter)
    if arm is None:
        return Section(result, None, f"not decided: {why_not}", cut)
    asp = aspects(arm)
    extent, covers = section_extent(arm, asp, sys.h, level, ax)
    if not covers and extent is not None:
        slack = mech.tolerances.equal * mech.length
        out = (extent[0] < box[0][0] - slack or extent[1] > box[0][1] + slack
               or extent[2] < box[1][0] - slack or extent[3] > box[1][1] + slack)
        if out:
            covers = (f"the box holds only part of the workspace's section ({x_axis} from {extent[0]:.4g} to "
                      f"{extent[1]:.4g} m, {y_axis} from {extent[2]:.4g} to {extent[3]:.4g} m)")
    points = [world(r.sample) for r in cut.regions]
    points += [world((a, b)) for a in np.linspace(*box[0], 21) for b in np.linspace(*box[1], 21)]
    span = max(box[0][1] - box[0][0], box[1][1] - box[1][0])
    ring = np.linspace(0, 2 * np.pi, 24, endpoint=False)
    points += [world((p[0] + r * np.cos(a), p[1] + r * np.sin(a))) for p, _ in cusps for r in (0.003 * span, 0.01 * span, 0.03 * span)
               for a in ring]
    counted = all(r.modes is not None for r in cut.regions)
    # a reversal of the trace at a singular point of det J = 0 (its factors' curves meeting: four solutions
    # there) is no cusp: a cusp lies on a smooth part of the singular set
    model = mech.model
    real, meets = [], []
    for (c, qc) in zip(result.cusps, result.cusp_q):
        t = pin.difference(model, q0, qc)[arm.free]
        near = any(np.abs(np.angle(np.exp(1j * (np.array(t[1:]) - np.array(sp))))).max() < mech.tolerances.singular
                   for sp in asp.singular_points)
        (meets if near else real).append((c, qc))
    if meets:
        result = replace(result, cusps=tuple(c for c, _ in real), cusp_q=tuple(q for _, q in real),
                         notes=result.notes + (f"{len(meets)} reversals of the trace at "
                                               + ", ".join(f"({c[0][0][0]:.12g}, {c[0][0][1]:.12g})" for c in meets)
                                               + " lie where det J's factors' curves meet (four solutions there): "
                                               "not cusps",))
    v = verdict(arm, asp, points, len(real), covers, counted)
    return Section(result, v.cuspidal, v.rests_on, cut, v.generic, v.aspects,
                   None if extent is None else tuple(float(e) for e in extent))
