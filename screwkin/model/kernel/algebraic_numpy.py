"""The rows of model.kernel.algebraic.PolynomialClosure and their Jacobian, in numpy: world placements of the
joints and frames at a stack of complex points (the stack's index last inside), then the rows.

A homotopy evaluates the rows thousands of times on stacks of a few to a few hundred points, so the
work per call is what counts (numpy's overhead is about a microsecond a call, whatever the stack):
- only the joints the frames asked for hang from are placed (the rows read a few frames; the
  signature every one);
- a joint whose motion and whose ancestors' are all constant (inputs, eliminated legs, the ground)
  is placed once per ``set_inputs`` (``Placed.refresh``), not per call;
- each joint's rotation is folded with its placement in its parent: Lr R(c, s) = K0 + c K1 + s K2
  for a revolute, constants precomputed, so a level of the tree costs one 3 x 3 product and one
  product with a vector, whatever its joints.
The numbers are those of the compiled kernel (model.kernel.algebraic_compiled; tests compare them).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..geometry import quaternion_matrix, stack_cross, stack_mm, stack_mv

__all__ = ["Placed", "rows_all"]


class Placed:
    """How to place the frames ``frames`` (indices into closure.frames) of a PolynomialClosure, or
    every joint and frame (``frames`` None): the joints to place, level by level, and the constant
    ones placed once."""

    def __init__(self, closure: Any, frames: Any = None) -> None:
        c = self.closure = closure
        nj = c.nj
        self.frames = np.arange(len(c.frames)) if frames is None else np.asarray(frames, int)
        need = set(range(nj)) if frames is None else set().union(*(c._ancestors(j) for j in c.f_joint[self.frames]))
        need.add(0)
        variable = {j for j in need if any(c.passive[a] for a in c._ancestors(j))}
        self.const = np.array(sorted(need - variable), int)
        depth = np.zeros(nj, int)
        for j in range(1, nj):
            depth[j] = depth[c.parent[j]] + 1
        self.levels = []
        for d in range(1, depth.max(initial=0) + 1):
            js = np.array(sorted(j for j in variable if depth[j] == d), int)
            if not js.size:
                continue
            kinds = [c.kind[j] if c.passive[j] else "C" for j in js]
            sel = {k: np.array([i for i, x in enumerate(kinds) if x == k], int) for k in "RPC"}
            self.levels.append({
                "js": js, "ps": c.parent[js], "only": kinds[0] if len(set(kinds)) == 1 and kinds[0] in "RC" else None,
                "R": sel["R"], "R_c": np.array([c.slices[j].start for j in js[sel["R"]]], int),
                "R_t": np.array([c.tslices[j].start for j in js[sel["R"]]], int),
                "P": sel["P"], "P_u": np.array([c.slices[j].start for j in js[sel["P"]]], int),
                "P_t": np.array([c.tslices[j].start for j in js[sel["P"]]], int),
                "C": sel["C"], "Q": [(i, int(j)) for i, (j, x) in enumerate(zip(js, kinds)) if x in "SF"]})
        # the constants of the folded motions Lr R: (3, 3, joints) and (3, joints), stack axes last
        self.K = [stack_mm(c.Lr, M) for M in (c.ww, c.Pm, c.W)]
        self.La = stack_mv(c.Lr, c.axis.T)  # each joint's axis in its parent's frame
        self.refresh()

    def refresh(self) -> None:
        """The constant parts after closure.set_inputs: the constant joints' motions folded with
        their placements, and the world placements of the joints that are constant all the way up."""
        c = self.closure
        self.Lc = stack_mm(c.Lr, c.Rc)
        self.tcp = c.Lt + stack_mv(c.Lr, c.tc)
        oR = np.broadcast_to(np.eye(3, dtype=complex)[:, :, None], (3, 3, c.nj)).copy()
        op = np.zeros((3, c.nj), complex)
        for j in self.const[1:]:  # in tree order: a parent before its children
            p = c.parent[j]
            oR[:, :, j] = oR[:, :, p] @ self.Lc[:, :, j]
            op[:, j] = op[:, p] + oR[:, :, p] @ self.tcp[:, j]
        self.oRc, self.opc = oR, op

    def __call__(self, X: np.ndarray, jacobian: bool = True) -> dict:
        """World placements at the points X (P, n) (stack axis last): oR (3, 3, nj, P), op (3, nj, P)
        of the joints placed (the others are not filled in), fR, fp of the frames asked for (in
        their order); with ``jacobian`` each tangent coordinate's world rotation axis w (3, nt, P),
        centre o and translation direction e (a rotation's e and a slide's w are 0)."""
        c = self.closure
        Xt = np.asarray(X, complex).T  # (n, P)
        P = Xt.shape[1]
        oR = np.empty((3, 3, c.nj, P), complex)
        op = np.empty((3, c.nj, P), complex)
        oR[:, :, self.const] = self.oRc[:, :, self.const, None]
        op[:, self.const] = self.opc[:, self.const, None]
        if jacobian:
            w, o, e = (np.zeros((3, c.nt, P), complex) for _ in range(3))
        for lv in self.levels:
            js, ps = lv["js"], lv["ps"]
            Rp, opp = oR[:, :, ps], op[:, ps]
            if lv["only"] == "R":
                cs = lv["R_c"]
                L = (self.K[0][:, :, js, None] + Xt[cs] * self.K[1][:, :, js, None]
                     + Xt[cs + 1] * self.K[2][:, :, js, None])
                t = c.Lt[:, js, None]
            elif lv["only"] == "C":
                L, t = self.Lc[:, :, js, None], self.tcp[:, js, None]
            else:
                L, t = self._mixed(lv, Xt)
            oR[:, :, js] = stack_mm(Rp, L)
            op[:, js] = opp + stack_mv(Rp, t)
            if not jacobian:
                continue
            k = lv["R"]
            if k.size:  # a revolute's axis through its origin (which its motion leaves in place)
                w[:, lv["R_t"]] = stack_mv(Rp[:, :, k], self.La[:, js[k], None])
                o[:, lv["R_t"]] = op[:, js[k]]
            k = lv["P"]
            if k.size:
                e[:, lv["P_t"]] = stack_mv(Rp[:, :, k], self.La[:, js[k], None])
            for i, j in lv["Q"]:  # three revolutes about the joint frame's axes through the body's origin
                tl = c.tslices[j]
                rot = np.arange(tl.stop - 3, tl.stop)
                A = stack_mm(Rp[:, :, i], c.Lr[:, :, j, None])
                w[:, rot] = A
                o[:, rot] = op[:, j][:, None]
                if c.kind[j] == "F":
                    e[:, tl.start + np.arange(3)] = A
        fj = c.f_joint[self.frames]
        oRf = oR[:, :, fj]
        out = {"oR": oR, "op": op, "fR": stack_mm(oRf, c.f_R[:, :, self.frames, None]),
               "fp": op[:, fj] + stack_mv(oRf, c.f_t[:, self.frames, None])}
        if jacobian:
            out.update(w=w, o=o, e=e)
        return out

    def _mixed(self, lv: dict, Xt: np.ndarray) -> Any:
        """(L, t) of a level with joints of several kinds: each joint's folded motion Lr R and its
        translation Lt + Lr t in its parent's frame, (3, 3, joints, P) and (3, joints, P)."""
        c, js = self.closure, lv["js"]
        P = Xt.shape[1]
        L = np.empty((3, 3, len(js), P), complex)
        t = np.empty((3, len(js), P), complex)
        k = lv["R"]
        if k.size:
            jr, cs = js[k], lv["R_c"]
            L[:, :, k] = self.K[0][:, :, jr, None] + Xt[cs] * self.K[1][:, :, jr, None] + Xt[cs + 1] * self.K[2][:, :, jr, None]
            t[:, k] = c.Lt[:, jr, None]
        k = lv["P"]
        if k.size:
            jp = js[k]
            L[:, :, k] = c.Lr[:, :, jp, None]
            t[:, k] = c.Lt[:, jp, None] + Xt[lv["P_u"]] * self.La[:, jp, None]
        k = lv["C"]
        if k.size:
            L[:, :, k], t[:, k] = self.Lc[:, :, js[k], None], self.tcp[:, js[k], None]
        for i, j in lv["Q"]:
            xj = Xt[c.slices[j]]
            L[:, :, i] = stack_mm(c.Lr[:, :, j, None], quaternion_matrix(xj[-4:].T).transpose(1, 2, 0))
            t[:, i] = c.Lt[:, j, None] + (stack_mv(c.Lr[:, :, j, None], xj[:3]) if c.kind[j] == "F" else 0.0)
        return L, t


def rows_all(c: Any, kin: dict, jacobian: bool) -> tuple[np.ndarray, np.ndarray | None]:
    """Every planned row of the closure c (before dropping the identically zero ones), (rows, P), and
    its Jacobian in tangent coordinates (rows, nt, P), from placements ``kin`` (Placed's) of the
    frames the rows read (the first of c.frames)."""
    fR, fp = kin["fR"], kin["fp"]
    P, nt = fp.shape[-1], c.nt
    r = np.empty((c._nrows_all, P), complex)
    J: Any = np.empty((c._nrows_all, nt, P), complex) if jacobian else None
    v = stack_mv(fR[:, :, c.vq_f], c.vq_u[..., None])  # (3, vectors, P)
    if jacobian:
        w, o, e = kin["w"], kin["o"], kin["e"]
        mask_f = c.above[:fp.shape[1], :, None]
        dv = stack_cross(w[:, None], v[:, :, None]) * c.above[c.vq_f][None, :, :, None]  # (3, vectors, nt, P)
        dp = (stack_cross(w[:, None], fp[:, :, None] - o[:, None]) + e[:, None]) * mask_f[None]  # (3, frames, nt, P)
    x = c.rix["pos"]
    if len(x["a"]):
        r[x["rows"]] = (fp[:, x["b"]] - fp[:, x["a"]]).transpose(1, 0, 2)
        if jacobian:
            J[x["rows"]] = (dp[:, x["b"]] - dp[:, x["a"]]).transpose(1, 0, 2, 3)
    x = c.rix["vec"]
    if len(x["q1"]):
        r[x["rows"]] = (v[:, x["q1"]] - v[:, x["q2"]]).transpose(1, 0, 2)
        if jacobian:
            J[x["rows"]] = (dv[:, x["q1"]] - dv[:, x["q2"]]).transpose(1, 0, 2, 3)
    x = c.rix["dotd"]
    if len(x["q1"]):
        d = fp[:, x["b"]] - fp[:, x["a"]]
        u = v[:, x["q1"]]
        rows = x["rows"][:, 0]
        r[rows] = (u * d).sum(0)
        if jacobian:
            J[rows] = (dv[:, x["q1"]] * d[:, :, None]).sum(0) + (u[:, :, None] * (dp[:, x["b"]] - dp[:, x["a"]])).sum(0)
    x = c.rix["dist"]
    if len(x["a"]):
        d = fp[:, x["b"]] - fp[:, x["a"]]
        rows = x["rows"][:, 0]
        r[rows] = (d * d).sum(0) - c.r2[x["q1"]][:, None]
        if jacobian:
            J[rows] = 2 * (d[:, :, None] * (dp[:, x["b"]] - dp[:, x["a"]])).sum(0)
    x = c.rix["dot"]
    if len(x["q1"]):
        v1, v2 = v[:, x["q1"]], v[:, x["q2"]]
        rows = x["rows"][:, 0]
        r[rows] = (v1 * v2).sum(0)
        if jacobian:
            J[rows] = (dv[:, x["q1"]] * v2[:, :, None]).sum(0) + (v1[:, :, None] * dv[:, x["q2"]]).sum(0)
    return r, J
