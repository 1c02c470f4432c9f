"""MuJoCo's own equality rows of a written MJCF, and which of them are redundant: export's note.

MuJoCo writes each equality as rows of its constraint Jacobian efc_J (engine_core_constraint.c):
a ``connect`` 3 rows, the difference of its two points along world x, y, z [m]; a ``weld`` 6, that
difference at the anchor, then the turn between the bodies (the vector part of q2^-1 q1 relpose,
about body2's axes); a ``joint`` equality 1.  At the written zero (qpos0) a set of rows is
redundant when the left null space of efc_J holds their forces: other rows can take them over, or
nothing moves along them.  The rows are taken in the order MuJoCo writes them (the file's): the
redundant directions of an equality are the forces f of its rows whose generalized force
J_e^T f the rows before it give already (J_e^T f in their row space), split into those that do no
work at all (J_e^T f = 0: nothing moves along them) and those that repeat earlier rows, which are
named.  Where a subspace is spanned by some of the rows themselves it is named by them (``the
forces along x, z``); otherwise by its directions.  MuJoCo writes no rows for an equality whose
Jacobian is zero at qpos0 (a point no joint moves); all its rows are then redundant, and said so.
MuJoCo is imported only here, when asked; without it nothing is named (the caller says so).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..tolerances import DEFAULT, Tolerances

__all__ = ["RedundantRows", "redundant_rows"]

#: What each row of an equality stands for, by MuJoCo's equality type name.
_ROWS = {"connect": ("force", "force", "force"), "weld": ("force",) * 3 + ("moment",) * 3, "joint": ("coupling",)}
_AXES = "xyz"


@dataclass(frozen=True)
class RedundantRows:
    """The redundant rows of one equality at qpos0.  ``idle``: directions (in words) of its rows
    along which nothing moves; ``repeated``: directions that rows of ``repeats`` (earlier
    equalities) give already; ``dropped``: MuJoCo writes none of its rows (a zero Jacobian)."""

    equality: str
    type: str
    rows: int
    idle: tuple = ()
    repeated: tuple = ()
    repeats: tuple = ()
    dropped: bool = False

    @property
    def count(self) -> int:
        return self.rows if self.dropped else len(self.idle) + len(self.repeated)

    def text(self) -> str:
        """``connect 'B~axis': the forces along x, y (repeating connect 'B'), the force along z (nothing moves
        along it)``."""
        head = f"{self.type} {self.equality!r}"
        if self.dropped:
            return f"{head}: all {self.rows} rows (its Jacobian is zero at qpos0: MuJoCo writes no rows for it)"
        parts = []
        if self.repeated:
            parts.append(f"{_join(self.repeated)} (repeating {', '.join(self.repeats)})")
        if self.idle:
            parts.append(f"{_join(self.idle)} (nothing moves along {'it' if len(self.idle) == 1 else 'them'})")
        return f"{head}: " + "; ".join(parts)

    def as_dict(self) -> dict:
        return {"equality": self.equality, "type": self.type, "rows": self.rows, "redundant": self.count,
                "idle": list(self.idle), "repeated": list(self.repeated), "repeats": list(self.repeats),
                "dropped": self.dropped, "text": self.text()}


def _join(words) -> str:
    """``the force along x``, ``the force along y`` -> ``the forces along x, y``."""
    merged, groups = [], {}
    for w in words:
        for head, plural in (("the force along ", "the forces along "), ("the moment about body2's ",
                                                                          "the moments about body2's ")):
            if w.startswith(head) and len(w) == len(head) + 1:
                if head not in groups:
                    groups[head] = [plural, []]
                    merged.append(groups[head])
                groups[head][1].append(w[-1])
                break
        else:
            merged.append(w)
    out = []
    for x in merged:
        if isinstance(x, list):
            plural, axes = x
            out.append(plural + ", ".join(axes) if len(axes) > 1 else plural.replace("forces", "force").replace(
                "moments", "moment") + axes[0])
        else:
            out.append(x)
    return ", ".join(out)


def _words(kind: str, basis: np.ndarray, tol: float) -> list:
    """Words for the subspace spanned by the columns of ``basis`` (orthonormal, in the equality's rows):
    the rows themselves where they span it (``the force along x``), else its directions."""
    labels = _ROWS[kind]
    k, s = basis.shape
    if s == 0:
        return []
    P = basis @ basis.T
    inside = [i for i in range(k) if np.linalg.norm(P[:, i] - np.eye(k)[:, i]) < tol]
    if len(inside) == s:
        return [_row_word(labels[i], i) for i in inside]
    out = []
    for v in basis.T:
        v = v / np.abs(v).max()
        if kind == "joint":
            out.append("the coupling")
            continue
        force, moment = v[:3], v[3:]
        parts = []
        if np.abs(force).max() > tol:
            parts.append(f"the force along ({', '.join(f'{x:.3g}' for x in force / np.linalg.norm(force))})")
        if moment.size and np.abs(moment).max() > tol:
            parts.append(f"the moment about ({', '.join(f'{x:.3g}' for x in moment / np.linalg.norm(moment))})"
                         f"{' of body2' if kind == 'weld' else ''}")
        out.append(" with ".join(parts))
    return out


def _row_word(label: str, i: int) -> str:
    if label == "force":
        return f"the force along {_AXES[i % 3]}"
    if label == "moment":
        return f"the moment about body2's {_AXES[i % 3]}"
    return "the coupling"


def _column_basis(A: np.ndarray, tol: float) -> np.ndarray:
    """An orthonormal basis (columns) of the column space of A."""
    if A.size == 0:
        return np.zeros((A.shape[0], 0))
    U, s, _ = np.linalg.svd(A, full_matrices=False)
    return U[:, s > tol]


def _null_left(A: np.ndarray, tol: float) -> np.ndarray:
    """An orthonormal basis (columns) of {f : f^T A = 0}."""
    U, s, _ = np.linalg.svd(A, full_matrices=True)
    r = int(np.sum(s > tol))
    return U[:, r:]


def redundant_rows(text: str, tol: Tolerances = DEFAULT) -> tuple:
    """(the number of equality rows MuJoCo writes at qpos0, RedundantRows of each equality of the
    MJCF ``text`` that has redundant ones, in the file's order), from MuJoCo's efc_J at qpos0 (dense;
    contacts and limits off).  Raises ImportError without MuJoCo."""
    import mujoco  # MuJoCo is optional: imported only when asked

    m = mujoco.MjModel.from_xml_string(text)
    m.opt.jacobian = mujoco.mjtJacobian.mjJAC_DENSE
    m.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CONTACT) | int(mujoco.mjtDisableBit.mjDSBL_LIMIT)
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    J = d.efc_J[:d.nefc * m.nv].reshape(d.nefc, m.nv)[:d.ne] if d.nefc else np.zeros((0, m.nv))
    ids = np.asarray(d.efc_id[:d.ne], int)
    scale = max(float(np.abs(J).max()) if J.size else 0.0, 1.0)
    cut = max(tol.rank_rtol * scale, tol.rank_atol)
    kinds = {int(mujoco.mjtEq.mjEQ_CONNECT): "connect", int(mujoco.mjtEq.mjEQ_WELD): "weld",
             int(mujoco.mjtEq.mjEQ_JOINT): "joint"}
    out = []
    for e in range(m.neq):
        kind = kinds.get(int(m.eq_type[e]))
        if kind is None or not m.eq_active0[e]:
            continue
        name = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_EQUALITY, e) or f"{kind}{e + 1}"
        rows = np.flatnonzero(ids == e)
        if rows.size == 0:
            out.append(RedundantRows(name, kind, len(_ROWS[kind]), dropped=True))
            continue
        Je = J[rows]
        before = J[: rows[0]]
        Q = _column_basis(before.T, cut)  # the row space of the rows before, as columns in R^nv
        free = _null_left(Je - (Je @ Q) @ Q.T, cut)  # f: J_e^T f in that row space
        if free.shape[1] == 0:
            continue
        idle = _null_left(Je, cut)  # J_e^T f = 0: inside ``free`` already
        rest = _column_basis(free - idle @ (idle.T @ free), cut)  # the rest of free: what earlier rows give
        repeats = []
        if rest.shape[1]:
            g = np.linalg.lstsq(before.T, Je.T @ rest, rcond=None)[0]
            for f in sorted({int(ids[r]) for r in np.flatnonzero(np.abs(g).max(axis=1) > tol.geometry)}):
                other = kinds.get(int(m.eq_type[f]), "equality")
                repeats.append(f"{other} {mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_EQUALITY, f) or f + 1!r}")
        out.append(RedundantRows(name, kind, len(rows), tuple(_words(kind, idle, tol.geometry)),
                                 tuple(_words(kind, rest, tol.geometry)), tuple(repeats)))
    return int(d.ne), out
