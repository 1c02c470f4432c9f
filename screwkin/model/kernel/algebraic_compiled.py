"""The rows of model.kernel.algebraic.PolynomialClosure and their Jacobian, compiled (numba; optional).

The same numbers as the numpy evaluation (tests compare the two at random complex points), one
path at a time in compiled loops (one core): a homotopy
tracks tens to thousands of paths, each step evaluating the rows a few times, and numpy's
overhead per call (about a hundred calls per evaluation) dominates for small stacks.  Used by
PolynomialClosure when numba imports (``compiled=None``), or when asked (``compiled=True``).
The kernel is compiled at its first use and cached on disk.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .compiled import cache_on_disk

__all__ = ["kernel", "pack"]

_KERNEL = None
#: The compiled helpers, set by _build (module globals: numba resolves them when it compiles a caller).
_MOTION = _AXES = _PLACE = _FRAMES = _VALUE = _DERIVATIVE = _ONE = None
POS, VEC, DOTD, DOT, DIST = 0, 1, 2, 3, 4
_KIND = {"": 0, "R": 1, "P": 2, "S": 3, "F": 4}


def pack(closure: Any) -> tuple:
    """The closure's constants as the kernel's arrays (layout of model.kernel.algebraic, stack axes first)."""
    nj = closure.nj
    xs = np.full(nj, -1, np.int64)
    ts = np.full(nj, -1, np.int64)
    for j, sl in closure.slices.items():
        xs[j], ts[j] = sl.start, closure.tslices[j].start
    kind = np.array([_KIND[k] for k in closure.kind], np.int64)
    rows = []
    for row in closure.plan:
        k = row[0]
        if k == "pos":
            for c in range(3):
                rows.append((POS, closure.f_index[row[1]], closure.f_index[row[2]], c, np.zeros(3), np.zeros(3)))
        elif k == "vec":
            for c in range(3):
                rows.append((VEC, closure.f_index[row[1]], closure.f_index[row[3]], c, row[2], row[4]))
        elif k == "dotd":
            rows.append((DOTD, closure.f_index[row[1]], closure.f_index[row[3]], 0, row[2], np.zeros(3)))
        elif k == "dist":
            rows.append((DIST, closure.f_index[row[1]], closure.f_index[row[2]], row[3], np.zeros(3), np.zeros(3)))
        else:
            rows.append((DOT, closure.f_index[row[1]], closure.f_index[row[3]], 0, row[2], row[4]))
    rows = [r for r, keep in zip(rows, closure.keep) if keep]
    rk = np.array([r[0] for r in rows], np.int64)
    ra = np.array([r[1] for r in rows], np.int64)
    rb = np.array([r[2] for r in rows], np.int64)
    rc = np.array([r[3] for r in rows], np.int64)
    ru = np.array([r[4] for r in rows], float).reshape(-1, 3)
    rw = np.array([r[5] for r in rows], float).reshape(-1, 3)
    return (closure.parent.astype(np.int64), kind, np.array(closure.passive, bool), xs, ts,
            np.ascontiguousarray(closure.axis), np.ascontiguousarray(closure.Lr.transpose(2, 0, 1)),
            np.ascontiguousarray(closure.Lt.T), closure.f_joint.astype(np.int64),
            np.ascontiguousarray(closure.f_R.transpose(2, 0, 1)), np.ascontiguousarray(closure.f_t.T),
            np.ascontiguousarray(closure.above), rk, ra, rb, rc, ru, rw)


def kernel() -> Any:
    """The compiled function rows(X, Rc, tc, r2, *pack(closure), nt, jacobian) -> (r (P, m), J (P, m, nt))."""
    global _KERNEL
    if _KERNEL is None:
        _KERNEL = _build()
    return _KERNEL


def _build() -> Any:
    """Compile the kernel's functions (numba; loaded from the disk cache after the first time).  Each is
    a module-level function that calls the others through module globals set here, so that numba's
    cache finds it again in the next process (a closure over dispatchers would be compiled anew in
    every process, and its cache would grow by an entry each time)."""
    import numba as nb

    global _MOTION, _AXES, _PLACE, _FRAMES, _VALUE, _DERIVATIVE, _ONE
    jit = nb.njit(cache=cache_on_disk())
    _MOTION = jit(_joint_motion)
    _AXES = jit(_joint_axes)
    _PLACE = jit(_place_joints)
    _FRAMES = jit(_place_frames)
    _VALUE = jit(_row_value)
    _DERIVATIVE = jit(_row_jacobian)
    _ONE = jit(_one)
    return jit(_every_point)


def _one(x: np.ndarray, Rc: np.ndarray, tc: np.ndarray, r2: np.ndarray, parent: np.ndarray, kind: np.ndarray,
         passive: np.ndarray, xs: np.ndarray, ts: np.ndarray, axis: np.ndarray, Lr: np.ndarray, Lt: np.ndarray,
         fj: np.ndarray, fR: np.ndarray, ft: np.ndarray, above: np.ndarray, rk: np.ndarray, ra: np.ndarray,
         rb: np.ndarray, rc: np.ndarray, ru: np.ndarray, rw: np.ndarray, nt: int, jacobian: bool, r: np.ndarray,
         J: np.ndarray) -> None:
    """The rows (and Jacobian) of one point x into r (m,) and J (m, nt)."""
    oR, op, wv, ov, ev = _PLACE(x, Rc, tc, parent, kind, passive, xs, ts, axis, Lr, Lt, nt, jacobian)
    fp, fRw = _FRAMES(oR, op, fj, fR, ft)
    ua = np.zeros(3, np.complex128)
    ub = np.zeros(3, np.complex128)
    d = np.zeros(3, np.complex128)
    for i in range(rk.shape[0]):
        fa, fb = ra[i], rb[i]
        for a in range(3):
            ua[a] = fRw[fa, a, 0] * ru[i, 0] + fRw[fa, a, 1] * ru[i, 1] + fRw[fa, a, 2] * ru[i, 2]
            ub[a] = fRw[fb, a, 0] * rw[i, 0] + fRw[fb, a, 1] * rw[i, 1] + fRw[fb, a, 2] * rw[i, 2]
            d[a] = fp[fb, a] - fp[fa, a]
        r[i] = _VALUE(rk[i], rc[i], ua, ub, d, r2)
        if jacobian:
            _DERIVATIVE(i, rk[i], rc[i], fa, fb, fp, ua, ub, d, wv, ov, ev, above, nt, J)


def _every_point(X: np.ndarray, Rc: np.ndarray, tc: np.ndarray, r2: np.ndarray, parent: np.ndarray, kind: np.ndarray,
          passive: np.ndarray, xs: np.ndarray, ts: np.ndarray, axis: np.ndarray, Lr: np.ndarray, Lt: np.ndarray,
          fj: np.ndarray, fR: np.ndarray, ft: np.ndarray, above: np.ndarray, rk: np.ndarray, ra: np.ndarray,
          rb: np.ndarray, rc: np.ndarray, ru: np.ndarray, rw: np.ndarray, nt: int, jacobian: bool
          ) -> tuple[np.ndarray, np.ndarray]:
    """The rows of every point of X (P, n): r (P, m), J (P, m, nt)."""
    P, m = X.shape[0], rk.shape[0]
    r = np.empty((P, m), np.complex128)
    J = np.empty((P, m, nt if jacobian else 0), np.complex128)
    for p in range(P):
        _ONE(X[p], Rc, tc, r2, parent, kind, passive, xs, ts, axis, Lr, Lt, fj, fR, ft, above, rk, ra, rb, rc, ru, rw,
             nt, jacobian, r[p], J[p])
    return r, J


def _joint_motion(x: Any, j: int, k: int, xs: Any, axis: Any, passive: Any, Rc: Any, tc: Any, R: Any, t: Any) -> None:
    """Joint j's motion at the point x into R (3, 3) and t (3,): the constant one of an input joint, a
    revolute's (cos, sin) (k 1), a prismatic's length (2), a quaternion (3, spherical; 4, free, after
    its translation)."""
    for a in range(3):
        t[a] = 0.0
    if not passive[j]:
        for a in range(3):
            t[a] = tc[j, a]
            for b in range(3):
                R[a, b] = Rc[j, a, b]
    elif k == 1:
        c, s = x[xs[j]], x[xs[j] + 1]
        w0, w1, w2 = axis[j, 0], axis[j, 1], axis[j, 2]
        for a in range(3):
            for b in range(3):
                ww = axis[j, a] * axis[j, b]
                R[a, b] = ww + c * ((1.0 if a == b else 0.0) - ww)
        R[0, 1] -= s * w2
        R[0, 2] += s * w1
        R[1, 0] += s * w2
        R[1, 2] -= s * w0
        R[2, 0] -= s * w1
        R[2, 1] += s * w0
    elif k == 2:
        u = x[xs[j]]
        for a in range(3):
            t[a] = u * axis[j, a]
            for b in range(3):
                R[a, b] = 1.0 if a == b else 0.0
    else:
        q0 = xs[j] + (3 if k == 4 else 0)
        qx, qy, qz, qw = x[q0], x[q0 + 1], x[q0 + 2], x[q0 + 3]
        R[0, 0] = qw * qw + qx * qx - qy * qy - qz * qz
        R[0, 1] = 2 * (qx * qy - qw * qz)
        R[0, 2] = 2 * (qx * qz + qw * qy)
        R[1, 0] = 2 * (qx * qy + qw * qz)
        R[1, 1] = qw * qw - qx * qx + qy * qy - qz * qz
        R[1, 2] = 2 * (qy * qz - qw * qx)
        R[2, 0] = 2 * (qx * qz - qw * qy)
        R[2, 1] = 2 * (qy * qz + qw * qx)
        R[2, 2] = qw * qw - qx * qx - qy * qy + qz * qz
        if k == 4:
            for a in range(3):
                t[a] = x[xs[j] + a]


def _joint_axes(j: int, k: int, v: int, A: Any, oj: Any, op: Any, axis: Any, wv: Any, ov: Any, ev: Any) -> None:
    """The world axes of joint j's tangent coordinates from v on (A: its frame's rotation before the
    motion, oj its origin): the turning axis wv and a point on it ov, the sliding direction ev."""
    if k == 1:
        for a in range(3):
            ov[v, a] = oj[a]
            for b in range(3):
                wv[v, a] += A[a, b] * axis[j, b]
    elif k == 2:
        for a in range(3):
            for b in range(3):
                ev[v, a] += A[a, b] * axis[j, b]
    else:
        r0 = v + (3 if k == 4 else 0)
        for m in range(3):
            for a in range(3):
                wv[r0 + m, a] = A[a, m]
                ov[r0 + m, a] = op[j, a]
                if k == 4:
                    ev[v + m, a] = A[a, m]


def _place_joints(x: np.ndarray, Rc: np.ndarray, tc: np.ndarray, parent: np.ndarray, kind: np.ndarray,
                  passive: np.ndarray, xs: np.ndarray, ts: np.ndarray, axis: np.ndarray, Lr: np.ndarray,
                  Lt: np.ndarray, nt: int, jacobian: bool) -> tuple:
    """The pass down the tree: every joint's world placement (oR (nj, 3, 3), op (nj, 3)) and, with
    ``jacobian``, the world axes of the tangent coordinates (wv, ov, ev (nt, 3))."""
    nj = parent.shape[0]
    oR = np.zeros((nj, 3, 3), np.complex128)
    op = np.zeros((nj, 3), np.complex128)
    for a in range(3):
        oR[0, a, a] = 1.0
    wv = np.zeros((nt, 3), np.complex128)
    ov = np.zeros((nt, 3), np.complex128)
    ev = np.zeros((nt, 3), np.complex128)
    R = np.zeros((3, 3), np.complex128)
    t = np.zeros(3, np.complex128)
    A = np.zeros((3, 3), np.complex128)
    oj = np.zeros(3, np.complex128)
    for j in range(1, nj):
        p = parent[j]
        for a in range(3):
            oj[a] = op[p, a]
            for b in range(3):
                oj[a] += oR[p, a, b] * Lt[j, b]
                s = 0.0 + 0.0j
                for c in range(3):
                    s += oR[p, a, c] * Lr[j, c, b]
                A[a, b] = s
        k = kind[j]
        _MOTION(x, j, k, xs, axis, passive, Rc, tc, R, t)
        for a in range(3):
            op[j, a] = oj[a]
            for b in range(3):
                op[j, a] += A[a, b] * t[b]
                s = 0.0 + 0.0j
                for c in range(3):
                    s += A[a, c] * R[c, b]
                oR[j, a, b] = s
        if jacobian and passive[j]:
            _AXES(j, k, ts[j], A, oj, op, axis, wv, ov, ev)
    return oR, op, wv, ov, ev


def _place_frames(oR: Any, op: Any, fj: Any, fR: Any, ft: Any) -> tuple[Any, Any]:
    """World origins fp (nf, 3) and rotations (nf, 3, 3) of the frames the rows read."""
    nf = fj.shape[0]
    fp = np.zeros((nf, 3), np.complex128)
    fRw = np.zeros((nf, 3, 3), np.complex128)
    for f in range(nf):
        j = fj[f]
        for a in range(3):
            fp[f, a] = op[j, a]
            for b in range(3):
                fp[f, a] += oR[j, a, b] * ft[f, b]
                s = 0.0 + 0.0j
                for c in range(3):
                    s += oR[j, a, c] * fR[f, c, b]
                fRw[f, a, b] = s
    return fp, fRw


def _row_value(kk: int, cc: int, ua: Any, ub: Any, d: Any, r2: Any) -> Any:
    """One row's value from the world vectors it reads (ua on frame a, ub on b, d = o_b - o_a)."""
    if kk == POS:
        return d[cc]
    if kk == VEC:
        return ua[cc] - ub[cc]
    if kk == DOTD:
        return ua[0] * d[0] + ua[1] * d[1] + ua[2] * d[2]
    if kk == DIST:
        return d[0] * d[0] + d[1] * d[1] + d[2] * d[2] - r2[cc]
    return ua[0] * ub[0] + ua[1] * ub[1] + ua[2] * ub[2]


def _row_jacobian(i: int, kk: int, cc: int, fa: int, fb: int, fp: Any, ua: Any, ub: Any, d: Any, wv: Any, ov: Any,
                  ev: Any, above: Any, nt: int, J: Any) -> None:
    """Row i's derivative along every tangent coordinate into J[i] (a coordinate moves a frame it is above)."""
    for v in range(nt):
        inA, inB = above[fa, v], above[fb, v]
        if not (inA or inB):
            J[i, v] = 0.0
            continue
        w0, w1, w2 = wv[v, 0], wv[v, 1], wv[v, 2]
        # moves of the points and vectors the row reads
        pa0 = pa1 = pa2 = pb0 = pb1 = pb2 = 0.0 + 0.0j
        if inA:
            x0, x1, x2 = fp[fa, 0] - ov[v, 0], fp[fa, 1] - ov[v, 1], fp[fa, 2] - ov[v, 2]
            pa0 = w1 * x2 - w2 * x1 + ev[v, 0]
            pa1 = w2 * x0 - w0 * x2 + ev[v, 1]
            pa2 = w0 * x1 - w1 * x0 + ev[v, 2]
        if inB:
            x0, x1, x2 = fp[fb, 0] - ov[v, 0], fp[fb, 1] - ov[v, 1], fp[fb, 2] - ov[v, 2]
            pb0 = w1 * x2 - w2 * x1 + ev[v, 0]
            pb1 = w2 * x0 - w0 * x2 + ev[v, 1]
            pb2 = w0 * x1 - w1 * x0 + ev[v, 2]
        da0 = da1 = da2 = db0 = db1 = db2 = 0.0 + 0.0j
        if inA:
            da0 = w1 * ua[2] - w2 * ua[1]
            da1 = w2 * ua[0] - w0 * ua[2]
            da2 = w0 * ua[1] - w1 * ua[0]
        if inB:
            db0 = w1 * ub[2] - w2 * ub[1]
            db1 = w2 * ub[0] - w0 * ub[2]
            db2 = w0 * ub[1] - w1 * ub[0]
        if kk == POS:
            J[i, v] = (pb0 - pa0) if cc == 0 else ((pb1 - pa1) if cc == 1 else (pb2 - pa2))
        elif kk == VEC:
            J[i, v] = (da0 - db0) if cc == 0 else ((da1 - db1) if cc == 1 else (da2 - db2))
        elif kk == DOTD:
            J[i, v] = (da0 * d[0] + da1 * d[1] + da2 * d[2]
                       + ua[0] * (pb0 - pa0) + ua[1] * (pb1 - pa1) + ua[2] * (pb2 - pa2))
        elif kk == DIST:
            J[i, v] = 2.0 * (d[0] * (pb0 - pa0) + d[1] * (pb1 - pa1) + d[2] * (pb2 - pa2))
        else:
            J[i, v] = (da0 * ub[0] + da1 * ub[1] + da2 * ub[2]
                       + ua[0] * db0 + ua[1] * db1 + ua[2] * db2)
