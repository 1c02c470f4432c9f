"""The loop-closure equations as polynomials, for complex coordinates: what the certified
assembly-mode search (analysis.position.certified) tracks.

Unknowns x (dimensionless), per passive joint of the spanning tree:
- revolute or continuous: (c, s), the cosine and sine of its angle, on the circle c^2 + s^2 = 1;
  its motion exp([w] theta) = w w^T + c (I - w w^T) + s [w] is linear in (c, s);
- prismatic: u = (value) / L (L: the characteristic length);
- ball (Pinocchio's spherical joint): its quaternion q = (x, y, z, w) on q.q = 1; its rotation, the
  homogeneous quadratic form Q(q), is quadratic, so q and -q are one placement (a symmetry,
  model.homotopy.symmetry);
- free flyer: three translations / L and a quaternion.
Input joints are constants (``set_inputs``).  Translations are divided by L, so every row is
dimensionless.

Rows (world vectors; o1, o2 the origins of the cut joint's frames F1, F2, R1, R2 their rotations):
    pos:  o2 - o1                 (fixed, revolute, universal, spherical)
    vec:  R1 u - R2 u             (u = the axis: revolute, cylindrical, planar; u = e_x, e_y: fixed,
                                   prismatic -- with det R = 1 these make R1 = R2)
    dotd: (R1 u) . (o2 - o1)      (u perpendicular to the axis: prismatic, cylindrical; the axis: planar)
    dot:  (R1 a) . (R2 a2)        (universal)
Their real zeros are exactly the closed configurations of model.kernel.closure (a revolute's axes aligned,
never antiparallel: the vector row R1 a = R2 a, not the perpendicularity rows).  Rows that vanish
identically on the constraint variety (a planar mechanism's out-of-plane rows) are dropped.

Points stay on the constraint variety (the circles and unit quaternions: a product of complex
circles and spheres): a step is taken in its tangent coordinates -- one angle per revolute, applied
as the complex rotation (c, s) -> (c cos d - s sin d, s cos d + c sin d); one length per prismatic;
a rotation vector per quaternion, applied as q -> exp(d / 2) q -- which keep c^2 + s^2 and q.q as
they were (``retract``; it divides them by their square root too, so that round-off, large where
a path makes a big excursion, cannot make the point drift off the variety).  On the variety every rotation is complex orthogonal, and the Jacobian in
those coordinates is the geometric one: a revolute's column moves a point p by w x (p - o) and a
vector v by w x v (w its world axis, o its origin), a prismatic's moves points by its world axis, a
quaternion's are three revolutes about its frame's axes through its centre.
Everything is evaluated for a stack of points at once in complex arithmetic: in numpy by
model.kernel.algebraic_numpy (the stack's index last inside; 3 x 3 products as sums of broadcast products,
four times numpy's stacked matmul), or by the compiled kernel of model.kernel.algebraic_compiled.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pinocchio as pin

from . import algebraic_compiled, compiled as numba_kernels
from .algebraic_numpy import Placed, rows_all
from .contract import ClosureKernel
from ..geometry import perpendicular_basis, quaternion_matrix, quaternion_product, skew
from ..legs import distance_legs

__all__ = ["PolynomialClosure", "algebraic_obstacle"]

#: Joint models whose motion is polynomial in the unknowns above, by kind.
_KINDS = {"JointModelRX": "R", "JointModelRY": "R", "JointModelRZ": "R", "JointModelRevoluteUnaligned": "R",
          "JointModelRUBX": "R", "JointModelRUBY": "R", "JointModelRUBZ": "R",
          "JointModelRevoluteUnboundedUnaligned": "R",
          "JointModelPX": "P", "JointModelPY": "P", "JointModelPZ": "P", "JointModelPrismaticUnaligned": "P",
          "JointModelSpherical": "S", "JointModelFreeFlyer": "F"}
_WIDTH = {"R": 2, "P": 1, "S": 4, "F": 7}
#: A row this small (relative to the largest) at random points is round-off of a zero polynomial.
_ZERO_ROW = 1e-10
#: Below this |d|^2 the quaternion step exp(d) takes sin(r)/r from its series.
_SERIES = 1e-8
_TANGENT = {"R": 1, "P": 1, "S": 3, "F": 6}


def algebraic_obstacle(model: Any, cuts: Any, extra: Any = (), couplings: Any = ()) -> str | None:
    """Why the closure of these cut joints and rows is not polynomial in the unknowns above (a
    sentence), or None when it is."""
    for j in range(1, model.njoints):
        short = model.joints[j].shortname()
        if short not in _KINDS:
            what = "a mimic coupling" if "Mimic" in short else f"a {short.replace('JointModel', '')} joint"
            return f"joint '{model.names[j]}' is {what}"
    for c in cuts:
        if c.pair is not None:
            law = {"rolling": "rolling without slip", "gear": "a gear pair's no-slip law",
                   "helical": "a screw pair's lead", "contact": "a sliding contact (cam or pin in a slot)"}
            return f"loop joint '{c.name}' is {law.get(c.pair, c.pair)}, not polynomial in the angles"
        if c.type not in ("fixed", "revolute", "continuous", "prismatic", "cylindrical", "universal", "planar",
                          "spherical"):
            return f"loop joint '{c.name}' is of type {c.type}"
    for e in extra:
        kind = getattr(e, "kind", "contact")
        if kind == "angle":
            return f"link '{e.input}' is held at an absolute angle (--set-angle)"
        return f"'{e.name}' is a {'sliding contact' if kind == 'contact' else 'rolling or screw law'}"
    if couplings:
        return f"joint '{couplings[0].joint}' is coupled to '{couplings[0].mimics}' (<mimic>)"
    return None


class PolynomialClosure(ClosureKernel):
    """The closure rows of a model's cut joints as polynomials in the passive joints' unknowns.

    model, cuts: the Pinocchio model and model.cuts.CutJoint list (a model copy with a target frame
    for inverse kinematics works the same); frozen: velocity indices of the input joints (constants);
    length: L [m]; points: frame ids whose origins the signature holds; output: a frame id whose
    pose it holds."""

    def __init__(self, model: Any, cuts: Any, frozen: Any, length: float, points: Any = (), output: Any = None,
                 compiled: bool | None = None, eliminate: bool = True) -> None:
        """compiled: evaluate the rows with the numba kernel of model.kernel.algebraic_compiled (True), with
        numpy (False), or with the kernel when numba imports (None); eliminate: the legs that are
        distance constraints (model.legs) become one row each, their joints no unknowns."""
        self.model, self.cuts, self.L = model, list(cuts), float(length)
        frozen = set(int(f) for f in np.asarray(frozen, int).ravel())
        self.legs = distance_legs(model, self.cuts, frozen, self.L, [output] if output is not None else []) \
            if eliminate else []
        self.eliminated = {j for leg in self.legs for j in leg.joints}
        for j in self.eliminated:  # held like inputs: nothing the rows read depends on them any more
            frozen.update(range(model.joints[j].idx_v, model.joints[j].idx_v + model.joints[j].nv))
        data = model.createData()
        pin.forwardKinematics(model, data, pin.neutral(model))
        nj = self.nj = model.njoints
        self.parent = np.array([model.parents[j] for j in range(nj)], int)
        self.kind = [""] + [_KINDS[model.joints[j].shortname()] for j in range(1, nj)]
        self.passive = [False] + [not any(model.joints[j].idx_v + k in frozen for k in range(model.joints[j].nv))
                                  for j in range(1, nj)]
        self.axis = np.zeros((nj, 3))
        for j in range(1, nj):
            if self.kind[j] in "RP":
                S = np.asarray(data.joints[j].S).reshape(6, -1)[:, 0]
                a = S[3:] if self.kind[j] == "R" else S[:3]
                self.axis[j] = a / np.linalg.norm(a)
        # constants, stack axes last: (3, 3, joints) and (3, joints)
        self.W = np.array([skew(a) for a in self.axis]).transpose(1, 2, 0)
        self.ww = np.einsum("ji,jk->ikj", self.axis, self.axis)
        self.Pm = np.eye(3)[:, :, None] - self.ww
        self.Lr = np.array([model.jointPlacements[j].rotation for j in range(nj)]).transpose(1, 2, 0)
        self.Lt = (np.array([model.jointPlacements[j].translation for j in range(nj)]) / self.L).T
        # unknowns and tangent coordinates
        self.slices, self.tslices, start, tstart = {}, {}, 0, 0
        for j in range(1, nj):
            if self.passive[j]:
                self.slices[j] = slice(start, start + _WIDTH[self.kind[j]])
                self.tslices[j] = slice(tstart, tstart + _TANGENT[self.kind[j]])
                start += _WIDTH[self.kind[j]]
                tstart += _TANGENT[self.kind[j]]
        self.n, self.nt = start, tstart
        self.k = self.n - self.nt  # equations of the variety (circles, quaternion norms)
        self.rev = np.array([j for j in self.slices if self.kind[j] == "R"], int)
        self.pri = np.array([j for j in self.slices if self.kind[j] == "P"], int)
        self.quat = [j for j in self.slices if self.kind[j] in "SF"]
        self.rev_c = np.array([self.slices[j].start for j in self.rev], int)
        self.rev_t = np.array([self.tslices[j].start for j in self.rev], int)
        self.pri_u = np.array([self.slices[j].start for j in self.pri], int)
        self.pri_t = np.array([self.tslices[j].start for j in self.pri], int)
        self.tjoint = np.zeros(self.nt, int)
        for j, sl in self.tslices.items():
            self.tjoint[sl] = j
        self._row_plan()
        on_leg = lambda f: model.frames[f].parentJoint in self.eliminated  # noqa: E731
        self.point_frames = [f for f in points if not on_leg(f)]
        self.output = output
        frames = self.row_frames + self.point_frames + ([output] if output is not None else [])
        self.frames = list(dict.fromkeys(frames))
        self.f_index = {f: k for k, f in enumerate(self.frames)}
        spec = {f: (model.frames[f].parentJoint, model.frames[f].placement.rotation, model.frames[f].placement.translation)
                for f in self.frames if not isinstance(f, tuple)}
        spec.update({("O", k): (leg.parent, np.eye(3), np.array(leg.centre)) for k, leg in enumerate(self.legs)})
        self.f_joint = np.array([spec[f][0] for f in self.frames], int)
        self.f_R = np.array([spec[f][1] for f in self.frames]).reshape(-1, 3, 3).transpose(1, 2, 0)
        self.f_t = (np.array([spec[f][2] for f in self.frames]).reshape(-1, 3) / self.L).T
        ancestors = [self._ancestors(j) for j in range(nj)]
        self.above = np.array([[self.tjoint[v] in ancestors[fj] for v in range(self.nt)] for fj in self.f_joint],
                              bool).reshape(len(self.frames), self.nt)
        self._row_index()
        self.Rc = np.broadcast_to(np.eye(3, dtype=complex)[:, :, None], (3, 3, nj)).copy()
        self.tc = np.zeros((3, nj), complex)
        self._placed: dict[Any, Placed] = {}  # frames placed (None: all, "rows": the rows') -> algebraic_numpy.Placed
        self.set_inputs(pin.neutral(model))
        self.keep = np.ones(self._nrows_all, bool)
        self.keep = self._nonzero_rows()
        self.m = int(self.keep.sum())
        self.nq, self.nv = self.n, self.nt  # the contract's: unknowns and tangent coordinates
        self.length_rows, self.sliding = np.zeros(self.m, bool), np.zeros(0, int)  # (lengths already over L)
        self._kernel = None
        if compiled or (compiled is None and numba_kernels.available()):
            self._kernel, self._packed = algebraic_compiled.kernel(), algebraic_compiled.pack(self)

    @property
    def compiled(self) -> bool:
        """Whether the rows are evaluated by the compiled kernel."""
        return self._kernel is not None

    # ------------------------------------------------------------------ layout
    def _ancestors(self, j: int) -> set:
        out = set()
        while j > 0:
            out.add(j)
            j = self.parent[j]
        return out

    def _row_plan(self) -> None:
        """Per cut joint its rows: ("pos", f1, f2), ("vec", f1, u1, f2, u2), ("dotd", f1, u, f2),
        ("dot", f1, u, f2, w), u in F1 and w in F2 (axes of the cut joint's frames)."""
        plan: list[tuple] = []
        frames: list = []
        self.row_cut: list[str] = []
        legs = {leg.cut: k for k, leg in enumerate(self.legs)}
        for cut in self.cuts:
            if cut.name in legs:  # a leg that is a distance: |p - O|^2 - r^2
                k = legs[cut.name]
                plan.append(("dist", ("O", k), self.legs[k].other, k))
                frames += [("O", k), self.legs[k].other]
                self.row_cut.append(cut.name)
                continue
            a = np.asarray(cut.axis, float)
            a = a / np.linalg.norm(a)
            b1, b2 = perpendicular_basis(a)
            f1, f2 = cut.frame1, cut.frame2
            frames += [f1, f2]
            t = cut.type
            ex, ey = np.eye(3)[0], np.eye(3)[1]
            rows: list[tuple] = []
            if t in ("fixed", "revolute", "continuous", "universal", "spherical"):
                rows.append(("pos", f1, f2))
            if t in ("fixed", "prismatic"):
                rows += [("vec", f1, ex, f2, ex), ("vec", f1, ey, f2, ey)]
            if t in ("revolute", "continuous", "cylindrical", "planar"):
                rows.append(("vec", f1, a, f2, a))
            if t in ("prismatic", "cylindrical"):
                rows += [("dotd", f1, b1, f2), ("dotd", f1, b2, f2)]
            if t == "planar":
                rows.append(("dotd", f1, a, f2))
            if t == "universal":
                a2 = np.asarray(cut.axis2, float)
                rows.append(("dot", f1, a, f2, a2 / np.linalg.norm(a2)))
            plan += rows
            self.row_cut += [cut.name] * sum(3 if r[0] in ("pos", "vec") else 1 for r in rows)
        self.plan = plan
        self.row_frames = list(dict.fromkeys(frames))
        self._nrows_all = len(self.row_cut)

    def _row_index(self) -> None:
        """Index arrays of the rows by kind: the frames and world vectors each reads, its row numbers."""
        vq: list[tuple[int, np.ndarray]] = []
        vq_key: dict[tuple, int] = {}

        def vector(f: Any, u: np.ndarray) -> Any:
            key = (f, tuple(np.round(u, 15)))
            if key not in vq_key:
                vq_key[key] = len(vq)
                vq.append((self.f_index[f], np.asarray(u, float)))
            return vq_key[key]

        idx: dict[str, dict[str, list]] = {k: {"rows": [], "a": [], "b": [], "q1": [], "q2": []} for k in ("pos", "vec", "dotd", "dot", "dist")}
        i = 0
        for row in self.plan:
            kind = row[0]
            d = idx[kind]
            width = 3 if kind in ("pos", "vec") else 1
            d["rows"].append(list(range(i, i + width)))
            i += width
            if kind == "dist":
                d["a"].append(self.f_index[row[1]])
                d["b"].append(self.f_index[row[2]])
                d["q1"].append(row[3])
            elif kind == "pos":
                d["a"].append(self.f_index[row[1]])
                d["b"].append(self.f_index[row[2]])
            elif kind == "vec":
                d["q1"].append(vector(row[1], row[2]))
                d["q2"].append(vector(row[3], row[4]))
            elif kind == "dotd":
                d["a"].append(self.f_index[row[1]])
                d["b"].append(self.f_index[row[3]])
                d["q1"].append(vector(row[1], row[2]))
            else:
                d["q1"].append(vector(row[1], row[2]))
                d["q2"].append(vector(row[3], row[4]))
        widths = {"pos": 3, "vec": 3, "dotd": 1, "dot": 1, "dist": 1}
        self.rix = {k: {n: np.array(v, int).reshape(len(v), widths[k]) if n == "rows" else np.array(v, int)
                        for n, v in d.items()} for k, d in idx.items()}
        self.vq_f = np.array([f for f, _ in vq], int)
        self.vq_u = np.array([u for _, u in vq]).reshape(-1, 3).T

    def set_inputs(self, q: np.ndarray) -> None:
        """Take the input joints' (constant) motions from the real configuration q, and the eliminated
        legs' lengths there (their frame's distance from their centre: any leg angles give it)."""
        if self.legs:
            data = self.model.createData()
            pin.framesForwardKinematics(self.model, data, np.asarray(q, float))
            self.r2 = np.array([np.sum((data.oMf[leg.frame].translation - data.oMi[leg.parent].act(np.array(leg.centre)))
                                       ** 2) for leg in self.legs]) / self.L ** 2
        else:
            self.r2 = np.zeros(0)
        for j in range(1, self.model.njoints):
            if self.passive[j]:
                continue
            jm = self.model.joints[j]
            x = self._from_joint(j, np.asarray(q, float)[jm.idx_q:jm.idx_q + jm.nq])
            R, t = self._motion(j, x[None].astype(complex))
            self.Rc[:, :, j], self.tc[:, j] = R[0], t[0]
        for placed in self._placed.values():
            placed.refresh()

    def _from_joint(self, j: int, qj: np.ndarray) -> np.ndarray:
        kind = self.kind[j]
        if kind == "R":
            return np.array([np.cos(qj[0]), np.sin(qj[0])]) if len(qj) == 1 else np.array(qj, float)
        if kind == "P":
            return qj / self.L
        if kind == "F":
            return np.r_[qj[:3] / self.L, qj[3:]]
        return np.array(qj, float)

    def from_q(self, q: np.ndarray) -> np.ndarray:
        """The unknowns x (n,) of a real configuration q."""
        q = np.asarray(q, float)
        x = np.zeros(self.n)
        for j, sl in self.slices.items():
            jm = self.model.joints[j]
            x[sl] = self._from_joint(j, q[jm.idx_q:jm.idx_q + jm.nq])
        return x

    def to_q(self, x: np.ndarray, q_inputs: np.ndarray) -> np.ndarray:
        """The real configuration with the passive joints at the real parts of x and the inputs of q_inputs."""
        q = np.array(q_inputs, float)
        x = np.real(np.asarray(x))
        for j, sl in self.slices.items():
            jm = self.model.joints[j]
            v, kind = x[sl], self.kind[j]
            if kind == "R":
                q[jm.idx_q:jm.idx_q + jm.nq] = [np.arctan2(v[1], v[0])] if jm.nq == 1 else v / np.hypot(*v)
            elif kind == "P":
                q[jm.idx_q] = v[0] * self.L
            elif kind == "S":
                q[jm.idx_q:jm.idx_q + 4] = v / np.linalg.norm(v)
            else:
                q[jm.idx_q:jm.idx_q + 3] = v[:3] * self.L
                q[jm.idx_q + 3:jm.idx_q + 7] = v[3:] / np.linalg.norm(v[3:])
        return q

    def random_points(self, rng: np.random.Generator, P: int) -> np.ndarray:
        """P random complex points on the constraint variety (circles, unit quaternions)."""
        X = np.empty((P, self.n), complex)
        for j, sl in self.slices.items():
            kind = self.kind[j]
            if kind == "R":
                th = rng.normal(size=P) + 1j * rng.normal(size=P) * 0.5
                X[:, sl] = np.stack([np.cos(th), np.sin(th)], 1)
            elif kind == "P":
                X[:, sl] = (rng.normal(size=(P, 1)) + 1j * rng.normal(size=(P, 1))) * 0.5
            else:
                qv = rng.normal(size=(P, 4)) + 1j * rng.normal(size=(P, 4)) * 0.5
                qv = qv / np.sqrt(np.einsum("pi,pi->p", qv, qv))[:, None]
                if kind == "S":
                    X[:, sl] = qv
                else:
                    X[:, sl] = np.c_[(rng.normal(size=(P, 3)) + 1j * rng.normal(size=(P, 3))) * 0.5, qv]
        return X

    # ------------------------------------------------------------------ moving on the variety
    def retract(self, X: np.ndarray, dT: np.ndarray) -> np.ndarray:
        """The points X (P, n) moved by the tangent steps dT (P, nt) (see the module)."""
        X = np.array(X, complex)
        if self.rev.size:
            d = dT[:, self.rev_t]
            c, s = X[:, self.rev_c], X[:, self.rev_c + 1]
            cd, sd = np.cos(d), np.sin(d)
            c, s = c * cd - s * sd, s * cd + c * sd
            rho = np.sqrt(c * c + s * s)  # 1 but for round-off, which big excursions would let drift
            X[:, self.rev_c], X[:, self.rev_c + 1] = c / rho, s / rho
        if self.pri.size:
            X[:, self.pri_u] += dT[:, self.pri_t]
        for j in self.quat:
            sl, tl = self.slices[j], self.tslices[j]
            d = dT[:, tl][:, -3:] * 0.5
            z = np.einsum("pi,pi->p", d, d)
            r = np.sqrt(z)
            small = np.abs(z) < _SERIES
            sinc = np.where(small, 1 - z / 6, np.sin(np.where(small, 1.0, r)) / np.where(small, 1.0, r))
            u = np.c_[d * sinc[:, None], np.cos(r)]
            qn = quaternion_product(u, X[:, sl.stop - 4:sl.stop])
            X[:, sl.stop - 4:sl.stop] = qn / np.sqrt(np.einsum("pi,pi->p", qn, qn))[:, None]
            if self.kind[j] == "F":
                X[:, sl.start:sl.start + 3] += dT[:, tl][:, :3]
        return X

    def tangent(self, X: np.ndarray) -> np.ndarray:
        """dx/dt (P, n, nt): how the unknowns move along each tangent coordinate at X."""
        P = len(X)
        T = np.zeros((P, self.n, self.nt), complex)
        if self.rev.size:
            T[:, self.rev_c, self.rev_t] = -X[:, self.rev_c + 1]
            T[:, self.rev_c + 1, self.rev_t] = X[:, self.rev_c]
        if self.pri.size:
            T[:, self.pri_u, self.pri_t] = 1.0
        for j in self.quat:
            sl, tl = self.slices[j], self.tslices[j]
            q = X[:, sl.stop - 4:sl.stop]
            for k in range(3):
                e = np.zeros(4)
                e[k] = 0.5
                T[:, sl.stop - 4:sl.stop, tl.stop - 3 + k] = quaternion_product(np.broadcast_to(e, q.shape), q)
            if self.kind[j] == "F":
                T[:, sl.start + np.arange(3), tl.start + np.arange(3)] = 1.0
        return T

    # ------------------------------------------------------------------ kinematics
    def _motion(self, j: int, xj: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(R_E, t_E) of joint j at its unknowns xj (P, width): (P, 3, 3), (P, 3)."""
        P, kind = len(xj), self.kind[j]
        t = np.zeros((P, 3), complex)
        if kind == "R":
            R = (self.ww[:, :, j] + xj[:, 0, None, None] * self.Pm[:, :, j] + xj[:, 1, None, None] * self.W[:, :, j])
        elif kind == "P":
            R = np.broadcast_to(np.eye(3, dtype=complex), (P, 3, 3)).copy()
            t = xj[:, :1] * self.axis[j]
        elif kind == "S":
            R = quaternion_matrix(xj)
        else:
            R, t = quaternion_matrix(xj[:, 3:]), xj[:, :3].copy()
        return R, t

    def placed(self, which: Any = None) -> Placed:
        """How the numpy evaluation places the frames: every joint and frame (None) or the rows' ("rows")."""
        if which not in self._placed:
            self._placed[which] = Placed(self, None if which is None else np.arange(len(self.row_frames)))
        return self._placed[which]

    def kinematics(self, X: np.ndarray, jacobian: bool = True) -> dict:
        """World placements (stack axis last) of every joint frame (oR (3, 3, nj, P), op (3, nj, P))
        and of the frames the rows and points read (fR, fp); with ``jacobian`` each tangent
        coordinate's world axis w (3, nt, P), origin o and translation direction e (the module)."""
        return self.placed()(X, jacobian)

    # ------------------------------------------------------------------ equations
    def rows(self, X: np.ndarray, jacobian: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
        """The closure rows kept (P, m) and their Jacobian in tangent coordinates (P, m, nt)."""
        if self._kernel is not None:
            r, J = self._kernel(np.ascontiguousarray(X, complex), np.ascontiguousarray(self.Rc.transpose(2, 0, 1)),
                                np.ascontiguousarray(self.tc.T), np.asarray(self.r2, complex), *self._packed, self.nt,
                                jacobian)
            return r, (J if jacobian else None)
        r, Jall = rows_all(self, self.placed("rows")(X, jacobian), jacobian)
        return r[self.keep].T, (Jall[self.keep].transpose(2, 0, 1) if Jall is not None else None)

    def evaluate(self, Q: np.ndarray, jacobian: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
        """The contract's rows: ``rows`` at the complex points Q (N, n) (lengths over L: dimensionless),
        their Jacobian along the tangent coordinates (N, m, nt)."""
        return self.rows(Q, jacobian)

    def integrate(self, Q: np.ndarray, V: np.ndarray) -> np.ndarray:
        """The contract's step on the variety: ``retract`` of the points Q (N, n) by V (N, nt)."""
        return self.retract(Q, V)

    def constraints(self, X: np.ndarray) -> np.ndarray:
        """c^2 + s^2 - 1 per revolute, q.q - 1 per quaternion, at X (P, n): (P, k)."""
        X = np.asarray(X, complex)
        out = []
        for j, sl in self.slices.items():
            if self.kind[j] == "R":
                out.append(X[:, sl.start] ** 2 + X[:, sl.start + 1] ** 2 - 1.0)
            elif self.kind[j] in "SF":
                q = X[:, sl.stop - 4:sl.stop]
                out.append(np.einsum("pi,pi->p", q, q) - 1.0)
        return np.array(out).T.reshape(len(X), len(out))

    def _nonzero_rows(self) -> np.ndarray:
        """Rows that do not vanish identically on the constraint variety (tried at random complex points)."""
        X = self.random_points(np.random.default_rng(12345), 4)
        r, _ = rows_all(self, self.placed("rows")(X, jacobian=False), jacobian=False)
        size = np.abs(r).max(axis=1)
        return size > _ZERO_ROW * max(size.max(initial=0.0), 1.0)

    def residual_all(self, X: np.ndarray) -> np.ndarray:
        """Every planned row at X (P, rows) (the dropped ones too: they vanish identically)."""
        return rows_all(self, self.placed("rows")(X, jacobian=False), jacobian=False)[0].T

    def signature(self, X: np.ndarray) -> np.ndarray:
        """What tells assembly modes apart (analysis.position.position.PositionSolver.signature, in
        units of L, complex): every joint frame's origin (but the eliminated legs', which their ends
        fix), the points' and the output frame's pose."""
        kin = self.kinematics(X, jacobian=False)
        P = len(X)
        joints = [j for j in range(1, self.nj) if j not in self.eliminated]
        parts = [kin["op"][:, joints].transpose(2, 1, 0).reshape(P, -1)]
        if self.point_frames:
            idx = [self.f_index[f] for f in self.point_frames]
            parts.append(kin["fp"][:, idx].transpose(2, 1, 0).reshape(P, -1))
        if self.output is not None:
            k = self.f_index[self.output]
            parts += [kin["fp"][:, k].T, kin["fR"][:, :, k].transpose(2, 0, 1).reshape(P, 9)]
        return np.concatenate(parts, 1)


