"""Loop-closure equations of cut joints, their Jacobian, and the closure solver.

Every cut joint places a frame F1 on one link and F2 on another; the loop is
closed when F2 relative to F1 is a motion the joint allows.  The residual rows
of each joint type are scalar functions of the two world placements; their
derivatives are written with Pinocchio frame Jacobians expressed in
LOCAL_WORLD_ALIGNED (linear velocity of the frame origin, angular velocity,
both in world axes), so the rows of K(q) at a closed configuration are the
constraint wrenches of the cut joint (the reciprocal screws of the twists it
allows) in (force, moment) order.

Row kinds (world vectors; o1, o2 frame origins, d = o2 - o1):
  position along e (a unit vector fixed in F1):  r = e . d
  alignment of u (fixed in F1) with w (fixed in F2), kept perpendicular:  r = u . w
  full relative rotation:                         r = log3(R1^T R2)
"""

from __future__ import annotations

import threading
from typing import Any
from collections.abc import Callable

import numpy as np
import pinocchio as pin

from ...tolerances import DEFAULT, Tolerances
from . import compiled, newton
from .contract import ClosureKernel, Step, Verdict
from .contacts import contact_bias, contact_row
from .scaling import sliding_columns
from .wrenches import row_wrenches
from ..manifold import Integrator
from ..cuts import Assembly, CouplingRow
from ..geometry import cross3, perpendicular_basis, skew, skews, skews_batch
from ..linalg import complement
from .._pin import frame_jacobian

__all__ = ["ClosureSystem", "PinocchioKernel", "CompiledKernel"]

LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED


class _Workspace:
    """One thread's Data of a ClosureSystem, with the views into it that the rows read."""

    __slots__ = ("data", "placements", "groups", "buffers")

    def __init__(self, data: Any, placements: Any) -> None:
        self.data, self.placements = data, placements
        self.groups: Any = None
        self.buffers: Any = None


class ClosureSystem:
    """The loop-closure equations r(q) = 0 of a model with cut joints."""

    def __init__(self, model: Any, cuts: Any, tolerances: Tolerances = DEFAULT, path: str = "<mechanism>",
                 data: Any = None, extra: Any = ()) -> None:
        """data: the pinocchio.Data the building thread computes in (a new one when None; every other
        thread makes its own: ``_workspace``);
        extra: CouplingRow and ContactRow of higher pairs, after the cut joints' rows."""
        self.model = model
        self._first_data = model.createData() if data is None else data
        self._local = threading.local()  # per thread: its Data, the placements' views, the row groups
        self.cuts = list(cuts)
        self.extra = list(extra)
        self.tol = tolerances
        self.path = path
        self.nrows = sum(c.rows for c in self.cuts) + len(self.extra)
        self._basis = [perpendicular_basis(c.axis) for c in self.cuts]
        self._solver_rows: int | None = None
        self._compiled: tuple[Any, np.ndarray] | None = None  # (kernels, cut kinds) when accelerate() is on; each thread's buffers in its workspace
        self._free: dict[bytes, np.ndarray] = {}  # free velocity indices for each set of frozen ones
        self._plans = [self._plan(c, b1, b2) for c, (b1, b2) in zip(self.cuts, self._basis)]
        self._owner = threading.get_ident()
        self._position_rows: np.ndarray | None = None
        self.integrator = Integrator(model)  # q (+) dq on the model's configuration manifold, for stacks
        self._kernels: tuple[ClosureKernel, ...] = (PinocchioKernel(self),)

    # ------------------------------------------------------------------ per-thread workspace
    def _workspace(self) -> _Workspace:
        """This thread's Data, the views of its cut frames' placements and the row groups built
        on them: threads may share a mechanism (each computes in a Data of its own; the thread that
        built the system uses the Data it was given).  Pinocchio hands out its frame placements by
        reference and their rotation and translation as views of its own memory: read once here,
        they follow every forward-kinematics pass on that Data (fetching them costs about 1 us)."""
        ws = getattr(self._local, "ws", None)
        if ws is None:
            data = self._first_data if threading.get_ident() == self._owner else self.model.createData()
            placements = []
            for c in self.cuts:
                M1, M2 = data.oMf[c.frame1], data.oMf[c.frame2]
                placements.append((M1.rotation, M2.rotation, M1.translation, M2.translation))
            ws = self._local.ws = _Workspace(data, placements)
            ws.groups = self._group(placements)
        return ws

    @property
    def data(self) -> Any:
        """The pinocchio.Data this thread computes in."""
        return self._workspace().data

    @property
    def _placements(self) -> list:
        return self._workspace().placements

    @property
    def _groups(self) -> list:
        return self._workspace().groups

    @property
    def plans(self) -> list:
        """Per cut joint, the constant parts of its rows (see ``_plan``): position axes P in F1,
        alignment pairs (u in F1, w in F2), the vectors the solver rows compare (None: the
        alignments instead), and whether the minimal rows hold a rotation vector."""
        return list(self._plans)

    @property
    def position_rows(self) -> np.ndarray:
        """Mask of the minimal rows (``evaluate(solver=False)``) that are positions [m]; the
        others are dimensionless (angles, alignments)."""
        if self._position_rows is None:
            self._position_rows = np.array([":pos" in label for label in self.row_labels()], bool)
        return self._position_rows

    # ------------------------------------------------------------------ compiled inner loop
    def accelerate(self, on: bool = True) -> bool:
        """Solve with the compiled kernels of screwkin.model.kernel.compiled (numba) when it is installed
        and every cut joint is fixed or spherical; returns whether they are in use."""

        self._compiled = None
        kinds = compiled.kinds_of(self.cuts) if on and not self.extra else None
        if kinds is not None and compiled.available():
            self._compiled = (compiled.kernels(), kinds)
            self._kernels = (self._kernels[0], CompiledKernel(self))
        return self._compiled is not None

    @property
    def accelerated(self) -> bool:
        return self._compiled is not None

    def _kinematics(self, q: np.ndarray, jacobian: bool, data: Any) -> None:
        """Pinocchio's pass for q in ``data`` (this thread's): frame placements, and the joint
        Jacobians if asked."""
        if jacobian:
            pin.computeJointJacobians(self.model, data, q)
            pin.updateFramePlacements(self.model, data)
        else:
            pin.framesForwardKinematics(self.model, data, q)

    # ------------------------------------------------------------------ residual
    def _rows(self, solver: bool) -> int:
        if not solver:
            return self.nrows
        if self._solver_rows is None:
            self._solver_rows = sum(self._cut_rows(c, plan, True) for c, plan in zip(self.cuts, self._plans))
            self._solver_rows += len(self.extra)
        return self._solver_rows

    def _plan(self, cut: Any, b1: np.ndarray, b2: np.ndarray) -> tuple:
        """Constant parts of a cut joint's rows, in its frames: position axes P (rows, in F1),
        alignment pairs (u in F1, w in F2), the vectors the solver rows compare, and
        whether the minimal rows hold a rotation vector."""
        a = np.asarray(cut.axis, float)
        t = cut.type
        if t in ("fixed", "revolute", "continuous", "universal", "spherical"):
            P = np.eye(3)  # the three axes of F1
        elif t in ("prismatic", "cylindrical"):
            P = np.vstack([b1, b2])
        else:  # planar
            P = a[None, :]
        if t in ("revolute", "continuous", "cylindrical", "planar"):
            pairs: tuple = ((b1, a), (b2, a))
        elif t == "universal":
            pairs = ((a, np.asarray(cut.axis2, float)),)
        else:
            pairs = ()
        if t == "universal":
            vectors = None  # the solver keeps the minimal (perpendicularity) row
        elif t == "spherical":
            vectors = np.zeros((0, 3))
        else:
            vectors = np.eye(3) if t in ("fixed", "prismatic") else a[None, :]
        return P, pairs, vectors, t in ("fixed", "prismatic")

    def _group(self, placements: Any) -> list:
        """Cut joints of one type share the layout of their rows: each group is evaluated
        with stacked arrays (a few numpy calls per group, not per cut joint)."""
        offsets = {False: 0, True: 0}
        groups: dict[str, dict] = {}
        for c, cut in enumerate(self.cuts):
            P, pairs, vectors, rotation = self._plans[c]
            g = groups.setdefault(cut.type, {"members": [], "P": [], "U": [], "W": [], "V": [],
                                             "rows": {False: [], True: []}})
            g["members"].append(c)
            g["P"].append(P)
            g["U"].append([u for u, _ in pairs])
            g["W"].append([w for _, w in pairs])
            g["V"].append(vectors)
            g["rotation"] = rotation
            for solver in (False, True):
                n = self._cut_rows(cut, self._plans[c], solver)
                g["rows"][solver].append(np.arange(offsets[solver], offsets[solver] + n))
                offsets[solver] += n
        out = []
        for t, g in groups.items():
            P = np.array(g["P"])  # (n, k, 3)
            U = np.array(g["U"]).reshape(len(g["members"]), -1, 3)  # (n, p, 3) pair vectors in F1
            W = np.array(g["W"]).reshape(len(g["members"]), -1, 3)  # in F2
            V = None if g["V"][0] is None else np.array(g["V"]).reshape(len(g["members"]), -1, 3)
            identity = P.shape[1] == 3 and np.allclose(P, np.eye(3))
            out.append({
                "type": t, "members": g["members"], "P": None if identity else P, "k": P.shape[1],
                "U": U.transpose(0, 2, 1), "W": W.transpose(0, 2, 1),  # columns: (n, 3, p)
                "V": V, "V_identity": V is not None and V.shape[1] == 3 and np.allclose(V, np.eye(3)),
                "Vt": None if V is None else V.transpose(0, 2, 1), "rotation": g["rotation"],
                "frames1": [self.cuts[c].frame1 for c in g["members"]],
                "frames2": [self.cuts[c].frame2 for c in g["members"]],
                "views": [placements[c] for c in g["members"]],
                "rows": {s_: np.array(g["rows"][s_]) for s_ in (False, True)},
                "starts": {s_: [int(x[0]) if len(x) else 0 for x in g["rows"][s_]] for s_ in (False, True)},
            })
        return out

    @staticmethod
    def _cut_rows(cut: Any, plan: tuple, solver: bool) -> int:
        """Rows of one cut joint: 6 - dof minimal ones, or the solver's (positions, then three
        per shared vector, or the alignments of a universal joint), read from its plan."""
        if not solver:
            return cut.rows
        P, pairs, vectors, _ = plan
        return len(P) + (len(pairs) if vectors is None else 3 * len(vectors))

    def evaluate(self, q: np.ndarray, jacobian: bool = True, solver: bool = False
                ) -> tuple[np.ndarray, np.ndarray | None]:
        """Residual r(q) and, if asked, its Jacobian (rows x nv).

        With ``solver=False`` (default) the rows are the minimal ones (6 - dof per
        cut joint): at a closed configuration the Jacobian is the constraint
        Jacobian K whose rows are constraint wrenches.  With ``solver=True`` the
        orientation rows are replaced by smooth, redundant differences of world
        vectors (R2 e - R1 e), whose only root is the right one: these are what
        the closure solver drives to zero from far away.

        Rows of cut joint j, in order: positions e . d (e fixed in F1, d = o2 - o1),
        then (solver) R2 v - R1 v, or (minimal) log3(R1^T R2) or alignments u . w.
        """
        ws = self._workspace()
        model, data = self.model, ws.data
        self._kinematics(q, jacobian, data)
        nrows = self._rows(solver)
        r = np.empty(nrows)
        K: Any = np.empty((nrows, model.nv)) if jacobian else None
        for g in ws.groups:
            views = g["views"]
            n = len(views)
            if n <= 2:  # stacking pays from three cut joints of a type on (measured: 1 cut +7 us, 3 cuts -6 us)
                for j in range(n):
                    self._evaluate_one(g, j, r, K, solver, data)
                continue
            R1, R2, t1, t2 = (np.array([v[i] for v in views]) for i in range(4))  # (n, 3, 3), (n, 3)
            d = t2 - t1
            rows = g["rows"][solver]  # (n, rows per cut joint)
            k = g["k"]
            R1t = R1.transpose(0, 2, 1)
            E = R1t if g["P"] is None else g["P"] @ R1t  # (n, k, 3): position rows, F1 axes in the world
            r[rows[:, :k]] = (E @ d[:, :, None])[:, :, 0]
            if jacobian:
                J1 = np.array([frame_jacobian(model, data, f, LWA) for f in g["frames1"]])  # (n, 6, nv)
                J2 = np.array([frame_jacobian(model, data, f, LWA) for f in g["frames2"]])
                w1, w2 = J1[:, 3:], J2[:, 3:]
                # e . (v2 - v1) + (e x d) . w1
                K[rows[:, :k]] = E @ (J2[:, :3] - J1[:, :3] + skews_batch(d[:, :, None]) @ w1)
            rest = rows[:, k:]
            if solver and g["V"] is not None:
                if g["V"].shape[1] == 0:
                    continue
                # R2 v - R1 v for the vectors v that F1 and F2 must share; derivative
                # [R1 v]x w1 - [R2 v]x w2, all vectors of all cut joints in one product
                U1, U2 = (R1, R2) if g["V_identity"] else (R1 @ g["Vt"], R2 @ g["Vt"])  # (n, 3, m)
                m = U1.shape[2]
                r[rest] = (U2 - U1).transpose(0, 2, 1).reshape(n, 3 * m)
                if jacobian:
                    K[rest] = skews_batch(np.concatenate([U1, -U2], axis=2), m) @ np.concatenate([w1, w2], axis=1)
                continue
            if g["rotation"]:
                for j in range(n):
                    R = R1t[j] @ R2[j]
                    r[rest[j]] = pin.log3(R)
                    if jacobian:
                        K[rest[j]] = pin.Jlog3(R) @ R2[j].T @ (w2[j] - w1[j])
                continue
            if rest.shape[1]:  # alignments u . w, u fixed in F1, w in F2; derivative (w x u) . (w2 - w1)
                u, w = R1 @ g["U"], R2 @ g["W"]  # (n, 3, p)
                r[rest] = np.einsum("nip,nip->np", u, w)
                if jacobian:
                    c = np.stack([w[:, 1] * u[:, 2] - w[:, 2] * u[:, 1], w[:, 2] * u[:, 0] - w[:, 0] * u[:, 2],
                                  w[:, 0] * u[:, 1] - w[:, 1] * u[:, 0]], axis=1)  # (n, 3, p)
                    K[rest] = c.transpose(0, 2, 1) @ (w2 - w1)
        if self.extra:
            self._evaluate_extra(q, r, K, nrows - len(self.extra))
        return r, K

    def _evaluate_extra(self, q: np.ndarray, r: np.ndarray, K: np.ndarray, i: int) -> None:
        """The rows of the higher pairs (CouplingRow, ContactRow) from row i on."""
        for k, e in enumerate(self.extra, i):
            if isinstance(e, CouplingRow):
                r[k] = e.value(q)
                if K is not None:
                    K[k] = 0.0
                    for _, iv, c in e.terms:
                        K[k, iv] += c
                continue
            value, grad = contact_row(self.model, self.data, e, K is not None)
            r[k] = value
            if K is not None:
                K[k] = grad

    def _evaluate_one(self, g: dict, j: int, r: np.ndarray, K: np.ndarray, solver: bool, data: Any) -> None:
        """The rows of cut joint j of a group (the same rows as the stacked code, with 2-D
        arrays: a test checks that both give the same numbers), placements in ``data``."""
        model = self.model
        R1, R2, t1, t2 = g["views"][j]
        i = g["starts"][solver][j]  # the cut joint's rows are r[i:i + k] (positions), then the rest
        d = t2 - t1
        k = g["k"]
        E = R1.T if g["P"] is None else g["P"][j] @ R1.T
        r[i:i + k] = E @ d
        jacobian = K is not None
        if jacobian:
            J1 = frame_jacobian(model, data, g["frames1"][j], LWA)
            J2 = frame_jacobian(model, data, g["frames2"][j], LWA)
            w1, w2 = J1[3:], J2[3:]
            K[i:i + k] = E @ (J2[:3] - J1[:3] + skew(d) @ w1)
        i += k
        if solver and g["V"] is not None:
            if g["V"].shape[1]:
                U1, U2 = (R1, R2) if g["V_identity"] else (R1 @ g["Vt"][j], R2 @ g["Vt"][j])
                m = U1.shape[1]
                r[i:i + 3 * m] = (U2 - U1).T.ravel()
                if jacobian:
                    K[i:i + 3 * m] = skews(np.hstack([U1, -U2]), m) @ np.vstack([w1, w2])
            return
        if g["rotation"]:
            R = R1.T @ R2
            r[i:i + 3] = pin.log3(R)
            if jacobian:
                K[i:i + 3] = pin.Jlog3(R) @ R2.T @ (w2 - w1)
            return
        p = g["U"].shape[2]
        if p:
            u, w = R1 @ g["U"][j], R2 @ g["W"][j]  # (3, p)
            r[i:i + p] = np.einsum("ip,ip->p", u, w)
            if jacobian:
                for c in range(p):
                    K[i + c] = cross3(w[:, c], u[:, c]) @ (w2 - w1)

    def bias(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """K'(q, v) v: the second time derivative of the (minimal) residual rows
        along a motion with joint velocity v and zero joint acceleration, from
        Pinocchio's classical frame accelerations.  Exact for position and
        alignment rows everywhere and for rotation rows at closed configurations."""
        model, data = self.model, self.data
        pin.forwardKinematics(model, data, q, v, np.zeros(model.nv))
        pin.updateFramePlacements(model, data)
        out = np.empty(self.nrows)
        i = 0

        # (d/dt u, d2/dt2 u) for u fixed in a frame turning at w with acceleration al
        def second(u: np.ndarray, w: np.ndarray, al: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            ud = cross3(w, u)
            return ud, cross3(al, u) + cross3(w, ud)

        for cut, (P, pairs, _, rotation), (R1, R2, t1, t2) in zip(self.cuts, self._plans, self._placements):
            d = t2 - t1
            V1 = pin.getFrameVelocity(model, data, cut.frame1, LWA)
            V2 = pin.getFrameVelocity(model, data, cut.frame2, LWA)
            A1 = pin.getFrameClassicalAcceleration(model, data, cut.frame1, LWA)
            A2 = pin.getFrameClassicalAcceleration(model, data, cut.frame2, LWA)
            w1, w2, al1, al2 = V1.angular, V2.angular, A1.angular, A2.angular
            dd, ddd = V2.linear - V1.linear, A2.linear - A1.linear
            # e fixed in F1: d2/dt2 (e . d) = e . (d'' - 2 w1 x d' - al1 x d + w1 x (w1 x d))
            wd = cross3(w1, d)
            g = ddd - 2.0 * cross3(w1, dd) - cross3(al1, d) + cross3(w1, wd)
            k = len(P)
            out[i:i + k] = P @ (R1.T @ g)
            i += k
            if rotation:
                out[i:i + 3] = pin.Jlog3(R1.T @ R2) @ R2.T @ (al2 - al1 + cross3(w2, w1))
                i += 3
                continue
            for u, w in pairs:
                u, w = R1 @ u, R2 @ w  # world vectors of the alignment row u . w
                ud, udd = second(u, w1, al1)
                wd, wdd = second(w, w2, al2)
                out[i] = udd @ w + 2 * ud @ wd + u @ wdd
                i += 1
        for e in self.extra:  # a coupling is linear in the coordinates: nothing
            out[i] = 0.0 if isinstance(e, CouplingRow) else contact_bias(self.model, self.data, e)
            i += 1
        return out

    def row_labels(self, solver: bool = False) -> list:
        """A name for each residual row: '<cut>:<kind>' (pos = F2 origin along an F1
        axis, align = axis alignment, rot = rotation vector, vec = vector difference)."""
        labels = []
        for cut in self.cuts:
            t = cut.type
            n_pos = 3 if t in ("fixed", "revolute", "continuous", "universal", "spherical") else (
                2 if t in ("prismatic", "cylindrical") else 1)
            labels += [f"{cut.name}:pos{k}" for k in range(n_pos)]
            if solver and t != "universal":
                nvec = 0 if t == "spherical" else (3 if t in ("fixed", "prismatic") else 1)
                labels += [f"{cut.name}:vec{k}{c}" for k in range(nvec) for c in "xyz"]
            elif t in ("fixed", "prismatic"):
                labels += [f"{cut.name}:rot{c}" for c in "xyz"]
            elif t in ("revolute", "continuous", "cylindrical", "planar"):
                labels += [f"{cut.name}:align{k}" for k in range(2)]
            elif t == "universal":
                labels += [f"{cut.name}:perp"]
        for e in self.extra:  # lengths [m]: position rows for the dimensionless measures; an angle is not
            if isinstance(e, CouplingRow) and e.kind == "angle":
                labels.append(f"{e.name}:angle")
                continue
            labels.append(f"{e.name}:pos-{e.kind if isinstance(e, CouplingRow) else 'contact'}")
        return labels

    def row_rates(self, values: dict) -> np.ndarray:
        """What each minimal row's time derivative is held at: the rate (or acceleration) ``values`` gives
        the input a row holds (CouplingRow.input; 0 when not given), else 0.  K q' = row_rates(rates)."""
        out = np.zeros(self.nrows)
        for k, e in enumerate(self.extra, self.nrows - len(self.extra)):
            if getattr(e, "input", None) is not None:
                out[k] = float(values.get(e.input, 0.0))
        return out

    @property
    def row_inputs(self) -> tuple:
        """The inputs that rows hold (CouplingRow.input: links whose absolute angle is given), in row order."""
        return tuple(e.input for e in self.extra if getattr(e, "input", None) is not None)

    def row_wrenches(self, q: np.ndarray) -> list:
        """What a unit force in each minimal row exerts (model.kernel.wrenches.row_wrenches)."""
        return row_wrenches(self.model, self.data, self.cuts, self._plans, self.extra, q)

    def residual(self, q: np.ndarray) -> np.ndarray:
        return self.evaluate(q, jacobian=False)[0]

    def jacobian(self, q: np.ndarray) -> np.ndarray:
        K = self.evaluate(q, jacobian=True)[1]
        assert K is not None
        return K

    def wrong_branch(self, q: np.ndarray, placed: bool = False) -> list:
        """Cut joints whose aligned axes are antiparallel (a spurious root of the
        alignment rows: the joint would be assembled upside down).  placed: the
        frame placements in self.data are already those of q."""
        if not placed:
            pin.framesForwardKinematics(self.model, self.data, q)
        bad = []
        for cut in self.cuts:
            if cut.type in ("revolute", "continuous", "cylindrical", "planar"):
                a = np.asarray(cut.axis)
                R1 = self.data.oMf[cut.frame1].rotation
                R2 = self.data.oMf[cut.frame2].rotation
                if (R1 @ a) @ (R2 @ a) < 0:
                    bad.append(cut.name)
        return bad

    # ------------------------------------------------------------------ solving
    def solve(self, q0: np.ndarray, frozen: Any = (), tolerances: Tolerances | None = None,
              trace: Callable[..., None] | None = None) -> Assembly:
        """Solve r(q) = 0 from q0 by damped Newton (model.kernel.newton.solve: Levenberg-Marquardt,
        minimum-norm steps).  frozen: velocity indices that must not move (the inputs); trace:
        optional callable(iteration, q, r, K, dq, accepted) recording the iterations (r and K in
        the solver's rows, see ``row_labels``).  Raises AssemblyError with the smallest residual
        reached when it fails, or when the solution assembles a cut joint upside down."""
        return newton.solve(self.kernel, q0, frozen, tolerances or self.tol, trace)

    def free_columns(self, frozen: Any) -> np.ndarray:
        """The velocity indices not in ``frozen`` (a sequence of indices; cached per set of frozen ones)."""
        frozen = np.asarray(frozen, int).ravel()
        key = frozen.tobytes()
        free = self._free.get(key)
        if free is None:
            free = self._free[key] = complement(self.model.nv, frozen)
        return free

    @property
    def kernel(self) -> ClosureKernel:
        """The solver's rows through the kernels' contract (what ``solve`` iterates on): compiled when
        accelerate() is on (model.kernel.compiled), else Pinocchio's, a configuration at a time."""
        return self._kernels[1 if self._compiled else 0]

    @property
    def pinocchio(self) -> ClosureKernel:
        """The solver's rows through the contract, evaluated by Pinocchio (never compiled)."""
        return self._kernels[0]

    @property
    def solver_position_rows(self) -> np.ndarray:
        """Mask of the solver's rows (``evaluate(solver=True)``) that are lengths [m] (positions; the
        couplings of rolling and screw pairs); the others are dimensionless."""
        mask = []
        for c, (P, pairs, vectors, _) in zip(self.cuts, self._plans):
            rest = self._cut_rows(c, (P, pairs, vectors, None), True) - len(P)
            mask += [True] * len(P) + [False] * rest
        return np.array(mask + [True] * len(self.extra), bool)


class PinocchioKernel(ClosureKernel):
    """A ClosureSystem's solver rows under the kernels' contract: Pinocchio's pass, one configuration
    of the stack at a time (a stack of one: the single solve)."""

    def __init__(self, system: ClosureSystem) -> None:
        self.system = system
        self.nq, self.nv, self.m = system.model.nq, system.model.nv, system._rows(True)
        self.length_rows = system.solver_position_rows
        self.sliding = sliding_columns(system.model)

    def _one(self, q: np.ndarray, jacobian: bool) -> tuple[np.ndarray, np.ndarray | None]:
        return self.system.evaluate(q, jacobian, True)

    def evaluate(self, Q: np.ndarray, jacobian: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
        if len(Q) == 1:
            r, K = self._one(Q[0], jacobian)
            return r[None], (None if K is None else K[None])
        rows = [self._one(q, jacobian) for q in Q]
        return np.array([r for r, _ in rows]), (np.array([K for _, K in rows]) if jacobian else None)

    def integrate(self, Q: np.ndarray, V: np.ndarray) -> np.ndarray:
        return self.system.integrator(Q, V)

    def constraint_jacobian(self, Q: np.ndarray) -> np.ndarray:
        return np.array([self.system.jacobian(q) for q in Q]).reshape(len(Q), self.system.nrows, self.nv)

    def bias(self, Q: np.ndarray, V: np.ndarray) -> np.ndarray:
        return np.array([self.system.bias(q, v) for q, v in zip(Q, V)]).reshape(len(Q), self.system.nrows)

    def free_columns(self, frozen: Any) -> np.ndarray:
        return self.system.free_columns(frozen)

    def reversed_joints(self, q: np.ndarray, placed: bool = False) -> list[str]:
        return self.system.wrong_branch(q, placed)

    def newton_parts(self) -> tuple[Step, Verdict]:
        return newton.one_step, newton.judge

    @property
    def name(self) -> str:
        return self.system.path


class CompiledKernel(PinocchioKernel):
    """The same rows through numba's kernels (model.kernel.compiled: fixed and spherical cut joints),
    with the compiled step and verdict."""

    def _one(self, q: np.ndarray, jacobian: bool) -> tuple[np.ndarray, np.ndarray | None]:
        return compiled.cut_rows(self.system, q, jacobian)

    def newton_parts(self) -> tuple[Step, Verdict]:
        assert self.system._compiled is not None
        return compiled.one_step, self.system._compiled[0].judge
