"""The loop constraints in velocity form and their Taylor series from Lie brackets of the joint screws.

A mechanism's loops stay closed along a motion exactly when, for every cut joint c, the twist of
F2's link relative to F1's is one the cut joint allows (Mueller, "Higher-order analysis of
kinematic singularities of lower pair linkages and serial manipulators", J. Mech. Robot. 10(1),
2018; "Local kinematic analysis of closed-loop linkages -- mobility, singularities, and
shakiness", J. Mech. Robot. 8(4), 2016):

    Phi_c(t) = sum_u sigma_cu S_u(t) y_u(t) = 0,

the sum over the *units*: every one-parameter screw of the tree joints (a revolute's axis, each
of a ball joint's three rotations) and of the cut joint's own freedoms (written as a chain of
one-parameter screws attached to F1: a ball as three rotations), with sigma = +1 for the units
that carry F2, -1 for those that carry F1 and for the cut joint's freedoms, 0 for the path both
share.  S_u(t) is the unit's screw (v, w) in the world at time t; y_u = m_u x_col(u) its rate (m_u = 1:
a Pinocchio mimic joint is a unit of its primary's column whose motion subspace holds the multiplier),
x the rates of the columns: the tree's velocity coordinates, then the cut joints' freedoms.  Couplings of coordinates (rolling and screw
pairs, a link's angle held) add sum c_k x_k = 0.

A screw fixed in a body that moves with the spatial twist W changes as S' = [W, S] (the Lie
bracket of se(3), ad_W S = (w_W x v_S + v_W x w_S, w_W x w_S)).  The body carrying unit u moves
with the twist of its *carriers*: the units of the joints between it and the ground (and, for a
ball, a free-flyer, a planar or a translation joint, whose motion subspace is constant in the
child's frame, the joint's own units; for a universal joint the units before it).  With the
Taylor coefficients x(t) = sum_k X[k] t^k and S_u(t) = sum_k S_u[k] t^k this gives every
coefficient in closed form:

    (k + 1) S_u[k+1] = sum_{m<=k} ad(W_u[m]) S_u[k-m],    W_u[m] = sum_{w carries u} sum_l S_w[l] y_w[m-l],
    Phi_c[k] = sum_u sigma_cu sum_l S_u[l] y_u[k-l] = A X[k] + R_k(X[0..k-1]),

A the loops' Jacobian at the configuration.  Phi = O(t^K) is the loops closed to order K + 1 in
the configuration.  The rows of a cut whose loop lies in a subgroup are kept in its algebra
(se(2) of a plane, so(3) about a point; see ``subalgebra``): its other rows vanish identically.
Everything is dimensionless: translations divided by the characteristic length L (a Lie algebra
automorphism of se(3)), sliding columns multiplied by it.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np
import pinocchio as pin

from ..model.kernel.scaling import dimensionless_twists
from ..model.cuts import ContactRow
from ..model.geometry import cross_last, perpendicular_basis
from ..model.state import KinematicState
from .screws import cut_twists

if TYPE_CHECKING:
    from ..model.mechanism import Mechanism
    from screwkin.model.cuts import CutJoint

__all__ = ["LoopSystem", "Series", "loop_system", "ad", "split", "subalgebra", "BODY_JOINTS", "SEQUENTIAL_JOINTS"]

#: Joints whose motion subspace is constant in the child's frame (their own units carry each other).
BODY_JOINTS = ("JointModelSpherical", "JointModelFreeFlyer", "JointModelPlanar", "JointModelTranslation")
#: Joints whose units are a chain: each carried by the ones before it (Pinocchio's universal, ZYX ball).
SEQUENTIAL_JOINTS = ("JointModelUniversal", "JointModelSphericalZYX")


def ad(W: np.ndarray, S: np.ndarray) -> np.ndarray:
    """ad_W S for twists (v, w) in the last axis of W and S (arrays (..., 6))."""
    vW, wW, vS, wS = W[..., :3], W[..., 3:], S[..., :3], S[..., 3:]
    return np.concatenate([cross_last(wW, vS) + cross_last(vW, wS), cross_last(wW, wS)], axis=-1)


@dataclass(frozen=True)
class LoopSystem:
    """The loops of a mechanism at one configuration, as the Taylor series above needs them.

    names:    the columns: the tree's velocity coordinates, then each cut joint's freedoms;
    tree:     how many of the columns are the tree's (nv);
    screws:   (units, 6) each unit's dimensionless screw at the configuration;
    column, multiplier: (units,) the column whose rate drives each unit, and the factor;
    carriers: (units, units) carriers[u, w]: unit w carries unit u;
    sigma:    (cuts, units) the units' signs in each cut's loop;
    basis:    per cut, the (rows, 6) map from a twist of the loop's algebra to its coordinates;
    couplings: (couplings, columns) the rows of linear couplings;
    scale:    (columns,) a column's rate is its dimensionless rate times this (L for sliding);
    length:   the characteristic length L [m];
    algebra:  "se(3)", "se(2)" or "so(3)": where every loop lies;
    supported: False when a part has no closed form here (note says which): the series is then
              not available, only A (from the minimal rows' Jacobian it would match)."""

    names: tuple
    tree: int
    screws: np.ndarray
    column: np.ndarray
    multiplier: np.ndarray
    carriers: np.ndarray
    sigma: np.ndarray
    basis: tuple
    couplings: np.ndarray
    scale: np.ndarray
    length: float
    algebra: str = "se(3)"
    supported: bool = True
    note: str | None = None
    cut_names: tuple = ()
    cut_columns: tuple = ()  # per cut joint, its freedoms' columns
    dropped: tuple = ()  # cut freedoms held at zero by the reduction to the algebra
    where: np.ndarray | None = None  # the algebra's normal (se(2)) or point (so(3), dimensionless)
    contacts: np.ndarray | None = None  # (rows, columns) the first-order rows of sliding contacts (no series)

    @property
    def rows(self) -> int:
        return sum(len(b) for b in self.basis) + len(self.couplings) + (0 if self.contacts is None else len(self.contacts))

    @property
    def columns(self) -> int:
        return len(self.names)

    def stack(self, P: np.ndarray) -> np.ndarray:
        """The constraint rows of P (units, 6): each cut's sum of sigma P in its algebra."""
        blocks = [E @ (s @ P) for E, s in zip(self.basis, self.sigma)]
        return np.concatenate(blocks) if blocks else np.zeros(0)

    @property
    def jacobian(self) -> np.ndarray:
        """A (rows, columns): Phi[0] = A X[0]."""
        n = self.columns
        A = np.zeros((self.rows, n))
        for k in range(n):
            y = np.where(self.column == k, self.multiplier, 0.0)
            A[:, k] = self.coupled(self.stack(self.screws * y[:, None]), np.eye(n)[k])
        return A

    def coupled(self, loops: np.ndarray, x: np.ndarray) -> np.ndarray:
        """The loop rows followed by the coupling rows of the column rates x (and, for A only, the
        contacts' first-order rows)."""
        out = np.concatenate([loops, self.couplings @ x]) if len(self.couplings) else loops
        return out if self.contacts is None else np.concatenate([out, self.contacts @ x])


class Series:
    """The Taylor coefficients of a motion's column rates X[0], X[1], ... and of the units' screws
    along it; ``residual()`` is R_k for the next order k (Phi[k] with X[k] = 0)."""

    def __init__(self, system: LoopSystem, x0: np.ndarray) -> None:
        self.sys = system
        self.X = [np.asarray(x0, float)]
        self.S = [system.screws]
        self.P = []  # P[m] (units, 6): sum_l S[l] y[m-l], up to the order pushed

    def _y(self, k: int) -> np.ndarray:
        return self.sys.multiplier * self.X[k][self.sys.column]

    def _p(self, m: int, with_last: bool=True) -> np.ndarray:
        terms = [self.S[l] * self._y(m - l)[:, None] for l in range(m + 1) if with_last or l > 0]
        return np.sum(terms, axis=0) if terms else np.zeros_like(self.sys.screws)

    def _next_screws(self):
        """S[k] for k = len(self.S), from X[0..k-1]."""
        k = len(self.S)
        while len(self.P) < k:
            self.P.append(self._p(len(self.P)))
        W = [self.sys.carriers @ self.P[m] for m in range(k)]
        return sum(ad(W[m], self.S[k - 1 - m]) for m in range(k)) / k

    def residual(self) -> np.ndarray:
        """R_k for k = len(X): the order-k coefficient of the constraint with X[k] = 0."""
        k = len(self.X)
        if len(self.S) <= k:
            self.S.append(self._next_screws())
        P = sum(self.S[l] * self._y(k - l)[:, None] for l in range(1, k + 1))
        return self.sys.coupled(self.sys.stack(P), np.zeros(self.sys.columns))

    def residual_change(self, V) -> np.ndarray:
        """(rows, m): how residual() changes when the last X pushed, X[j] (j = len(X) - 1 >= 1), changes
        by each column of V (columns, m).  R_{j+1} is affine in X[j]: X[j] enters it only through
        S[1] y[j] and through S[j+1] y[0], whose term ad(W[j], S[0]) / (j + 1) holds W[j]'s
        carriers @ (S[0] y[j]); so this is exact, the difference of two residuals without computing them."""
        j = len(self.X) - 1
        if j < 1:
            raise ValueError("residual_change needs X[1] or later pushed")
        sys_ = self.sys
        Y = (sys_.multiplier[:, None] * np.asarray(V, float)[sys_.column]).T  # (m, units)
        S0, S1 = self.S[0], self.S[1]
        W = np.einsum("uw,mwi->mui", sys_.carriers, S0[None] * Y[:, :, None])
        D = S1[None] * Y[:, :, None] + ad(W, S0[None]) * (self._y(0)[None, :, None] / (j + 1))
        zero = np.zeros(sys_.columns)
        return np.stack([sys_.coupled(sys_.stack(d), zero) for d in D], axis=1)

    def push(self, xk: np.ndarray) -> None:
        """Take X[k] = xk for the next order k."""
        if len(self.S) <= len(self.X):
            self.S.append(self._next_screws())
        self.X.append(np.asarray(xk, float))

    def copy(self) -> Series:
        other = Series.__new__(Series)
        other.sys, other.X, other.S, other.P = self.sys, list(self.X), list(self.S), list(self.P)
        return other


def _units(mech: Mechanism, state: KinematicState) -> tuple:
    """Every unit of the tree: (screw (v, w) at the world origin, column, multiplier), the carriers
    of each (a set of unit indices), the units of each joint, and a note when a joint has no closed
    form here.  A Pinocchio mimic joint is a unit of its primary's column (its motion subspace holds
    the multiplier)."""
    model = mech.model
    units, carriers, by_joint = [], [], {}
    note = None
    for j in range(1, model.njoints):
        short = model.joints[j].shortname()
        parent_units = sorted({u for a in model.supports[j][1:-1] for u in by_joint.get(a, ())})
        S = state.joint_twists(j)
        if short == "JointModelMimic":
            cols = [model.idx_vs[j]]
        else:
            cols = list(range(model.idx_vs[j], model.idx_vs[j] + model.nvs[j]))
            if model.nvs[j] > 1 and short not in BODY_JOINTS + SEQUENTIAL_JOINTS:
                note = note or f"joint '{model.names[j]}' ({short}) has no closed-form screw derivatives here"
        first = len(units)
        for k, col in enumerate(cols):
            units.append((S[:, k], col, 1.0))
            own = range(first, first + len(cols)) if short in BODY_JOINTS else range(first, first + k)
            carriers.append(set(parent_units) | set(own))
        by_joint[j] = list(range(first, len(units)))
    return units, carriers, by_joint, note


def subalgebra(screws: np.ndarray, tol: float) -> tuple:
    """("se(2)", normal) when every screw (v, w) lies in the planar motions normal to one direction,
    ("so(3)", point) when every one is a rotation about one point, else ("se(3)", None)."""
    rot = [s for s in screws if np.linalg.norm(s[3:]) > tol]
    if not rot:
        return "se(3)", None
    n = rot[0][3:] / np.linalg.norm(rot[0][3:])
    if all(np.linalg.norm(np.cross(s[3:], n)) <= tol * max(1.0, np.linalg.norm(s)) and
           abs(s[:3] @ n) <= tol * max(1.0, np.linalg.norm(s)) for s in screws):
        return "se(2)", n
    if len(rot) == len(screws):
        Wx = np.vstack([-pin.skew(s[3:]) for s in screws])  # v = p x w = -[w]x p
        v = np.concatenate([s[:3] for s in screws])
        p = np.linalg.lstsq(Wx, v, rcond=None)[0]
        if np.linalg.norm(Wx @ p - v) <= tol * max(1.0, np.linalg.norm(v)):
            return "so(3)", p
    return "se(3)", None


def split(kind: str, where: str, S: np.ndarray) -> tuple:
    """(the part of twists S (..., 6) in the algebra, the part in its complement m): se(2) normal to
    n: (v - (v.n) n, (w.n) n) and ((v.n) n, w - (w.n) n); so(3) about p: (p x w, w) and (v - p x w, 0).
    m is invariant under the algebra's brackets, so motions of units in the algebra stay in it."""
    S = np.asarray(S, float)
    v, w = S[..., :3], S[..., 3:]
    if kind == "se(2)":
        n = where
        vn, wn = (v @ n)[..., None] * n, (w @ n)[..., None] * n
        return np.concatenate([v - vn, wn], -1), np.concatenate([vn, w - wn], -1)
    inside = np.concatenate([np.cross(where, w), w], -1)
    return inside, S - inside


def coordinates(kind: str, where: str) -> np.ndarray:
    """The (rows, 6) map from a twist of the algebra to its coordinates: se(2) (v.e1, v.e2, w.n), so(3) w."""
    if kind == "se(2)":
        n = where
        e1, e2 = perpendicular_basis(n)
        Z = np.zeros(3)
        return np.array([np.r_[e1, Z], np.r_[e2, Z], np.r_[Z, n]])
    if kind == "so(3)":
        return np.hstack([np.zeros((3, 3)), np.eye(3)])
    return np.eye(6)


def _cut_units(mech: Mechanism, cut: CutJoint, state: KinematicState, kind: str, where: str, L: float) -> list:
    """The cut joint's freedoms as world twists [(name, twist, sliding)] (screws.cut_twists); a ball's
    three rotations about axes that put the algebra's own rotation last (e1, e2, n in a plane)."""
    # a sliding contact closes through a planar cut joint (its contact row apart); a rolling, gear or screw
    # pair through a weld (its coupling row apart): the cut joint's own freedoms either way
    free = cut_twists(mech, replace(cut, pair=None), state) or []
    if cut.type == "spherical" and kind == "se(2)":
        p = state.frame_placement(cut.frame1).translation
        axes = (*perpendicular_basis(where), where)
        free = [(f"{cut.name}[{k}]", np.concatenate([np.cross(p, u), u]), False) for k, u in enumerate(axes)]
    return free


def _add_cut_units(mech: Mechanism, state: KinematicState, kind: str, where_world: np.ndarray | None, L: float,
                   units: list, carriers: list, by_joint: dict, names: list[str],
                   slide: list[bool]) -> tuple[list[list[set[int]]], list[list[int]]]:
    """Append each cut joint's freedoms to the units (with their names, whether they slide, and the units that
    carry them): (each cut's two sides (the tree units under its frames), each cut's own units)."""
    model = mech.model
    sides_of, own_of = [], []
    for cut in mech.cuts:
        sides = []
        for f in (cut.frame1, cut.frame2):
            jid = model.frames[f].parentJoint
            sides.append({u for j in model.supports[jid][1:] for u in by_joint.get(j, ())})
        first = len(units)
        for k, (name, twist, sliding) in enumerate(_cut_units(mech, cut, state, kind, where_world, L)):
            names.append(name)
            slide.append(bool(sliding))
            units.append((np.asarray(twist, float), len(names) - 1, 1.0))
            carriers.append(set(sides[0]) | set(range(first, first + k)))
        sides_of.append(sides)
        own_of.append(list(range(first, len(units))))
    return sides_of, own_of


def _extra_rows(mech: Mechanism, q: np.ndarray, ncols: int, scale: np.ndarray,
                L: float) -> tuple[np.ndarray, np.ndarray | None, str | None]:
    """The closure's rows beyond the loops, dimensionless, in the ``ncols`` columns: (the couplings' rows, the
    sliding contacts' rows of K (first order only) or None, the note a sliding contact makes or None)."""
    nv = mech.nv
    couplings, contacts = [], []
    note = None
    K = None
    for i, e in enumerate(mech.closure.extra, mech.closure.nrows - len(mech.closure.extra)):
        if isinstance(e, ContactRow):  # first order only: its row of K, in the tree's columns
            note = note or f"'{e.name}' is a sliding contact (cam, pin in a slot): its series is not written here"
            K = mech.closure.jacobian(q) if K is None else K
            row = np.zeros(ncols)
            row[:nv] = K[i] * scale[:nv] / L
            contacts.append(row)
            continue
        row = np.zeros(ncols)
        for _, iv, cval in e.terms:
            row[iv] += cval
        couplings.append(row * scale / (1.0 if e.kind == "angle" else L))
    return (np.array(couplings, float).reshape(len(couplings), ncols),
            np.array(contacts, float).reshape(len(contacts), ncols) if contacts else None, note)


def loop_system(mech: Mechanism, q: np.ndarray, length: float | None = None, reduce: bool = True) -> LoopSystem:
    """The LoopSystem of ``mech`` at the assembled configuration q.

    With ``reduce``, when every tree screw lies in se(2) (a planar mechanism) or so(3) (a spherical
    one), and each cut joint's freedoms outside that algebra have independent parts in its
    complement m (so the loops hold them at zero at every order: the equations' m-part involves
    them alone), those freedoms are dropped and each loop is written in the algebra's coordinates:
    its m-rows vanish identically along every motion (they are the redundancy the plane or the
    sphere makes: ``dropped_rows`` counts them)."""
    L = float(length or mech.length)
    tol = mech.tolerances
    state = KinematicState(mech, q)
    units, carriers, by_joint, note = _units(mech, state)
    nv = mech.nv
    tree_units = len(units)
    tree_screws = np.array([u[0] for u in units], float).reshape(tree_units, 6)
    tree_screws[:, :3] /= L
    kind, where = subalgebra(tree_screws, tol.geometry) if reduce and tree_units else ("se(3)", None)
    where_world = None if where is None else (where if kind == "se(2)" else where * L)
    names = list(mech.coordinate_names)
    slide = list(mech.translational.astype(bool))
    sides_of, own_of = _add_cut_units(mech, state, kind, where_world, L, units, carriers, by_joint, names, slide)
    n_units = len(units)
    scale = np.where(np.array(slide, bool), L, 1.0)
    column = np.array([u[1] for u in units], int)
    mult = np.array([u[2] for u in units], float)
    screws = np.array([u[0] for u in units], float).reshape(n_units, 6)  # one screw (twist) a row
    # dimensionless: v / L, sliding columns times L (model.kernel.scaling)
    screws = np.ascontiguousarray(dimensionless_twists(screws.T, np.array(slide, bool)[column], L).T)
    carrier = np.zeros((n_units, n_units))
    for u, cs in enumerate(carriers):
        carrier[u, sorted(cs)] = 1.0
    sigma = np.zeros((len(mech.cuts), n_units))
    for c, (sides, own) in enumerate(zip(sides_of, own_of)):
        sigma[c, sorted(sides[1] - sides[0])] = 1.0
        sigma[c, sorted(sides[0] - sides[1])] = -1.0
        sigma[c, own] = -1.0
    couplings, contacts, contact = _extra_rows(mech, q, len(names), scale, L)
    note = note or contact
    keep = list(range(n_units))
    dropped = ()
    rows = [coordinates("se(3)", None)] * len(mech.cuts)
    if kind != "se(3)":
        _, outside = split(kind, where, screws)
        out = [u for u in range(n_units) if np.linalg.norm(outside[u]) > tol.geometry]
        held = all(u >= tree_units for u in out) and all(
            np.linalg.matrix_rank(outside[[u for u in own if u in out]], tol.geometry) == sum(u in out for u in own)
            for own in own_of)
        if held:
            keep = [u for u in range(n_units) if u not in out]
            dropped = tuple(names[column[u]] for u in out)
            rows = [coordinates(kind, where)] * len(mech.cuts)
        else:
            kind, where = "se(3)", None
    if dropped:
        cols = [k for k in range(len(names)) if names[k] not in dropped]
        remap = {old: new for new, old in enumerate(cols)}
        screws, mult = screws[keep], mult[keep]
        column = np.array([remap[column[u]] for u in keep], int)
        carrier, sigma = carrier[np.ix_(keep, keep)], sigma[:, keep]
        names, scale, couplings = [names[k] for k in cols], scale[cols], couplings[:, cols]
        contacts = None if contacts is None else contacts[:, cols]
    cut_cols = tuple(tuple(sorted({int(column[i]) for i, u in enumerate(keep) if u in own})) for own in own_of)
    return LoopSystem(tuple(names), nv, screws, column, mult, carrier, sigma, tuple(rows), couplings, scale, L,
                      kind, note is None, note, tuple(c.name for c in mech.cuts), cut_cols, dropped,
                      None if where is None else np.asarray(where, float), contacts)
