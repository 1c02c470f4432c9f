"""The vector-loop equations of a planar mechanism of revolute and prismatic joints, rolling, gear
and rack-and-pinion pairs (the no-slip law substituted: screwkin.analysis.course.rolling), in
symbols (sympy): the course solution's planar method (screwkin.analysis.course.equations).

- Links are numbered as a textbook does and as ``screwkin draw`` numbers them
  (screwkin.analysis.course.skeleton.numbering): the ground 1, then 2, 3, ... along the chain from the
  input.  Each moving link has one absolute angle theta_k (the ``link_angles`` of
  ``solve``: screwkin.analysis.motion.planar.LinkAngles, counterclockwise about the plane's normal
  from the ground's x axis); links joined by prismatic joints turn together and share the
  angle of the lowest-numbered one (the ground's links: constant angles).
- The independent loops are the fundamental cycles of a breadth-first spanning tree of the
  joint graph (links as nodes, joints as edges, from the ground): one loop per joint
  outside the tree, L = J - N + 1 of them (screwkin.analysis.course.cycles).
- Each loop is walked from the link nearest the ground; on each link a vector joins the
  centres of the joint it enters by and the joint it leaves by: r_k (length r_k, angle
  theta_k, or -r_k when it points the other way), a second vector on the same link (a
  ternary link) r_kb at angle theta_k + alpha_kb, with alpha_kb a constant.  On the ground
  the vectors have constant angles theta_1, theta_1b, ...
- A prismatic joint between a guide link g and a slider link s contributes x_s u + e_s n:
  x_s the slider coordinate along the guide (from the first revolute centre on g to the
  first revolute centre on s, counted positive at the configuration analysed), u the
  unit vector of the guide (angle beta_s: absolute on the ground, theta_g + beta_s on a
  moving guide), n = u turned +90 deg, e_s the constant offset.
- Constants whose value is 0 (an offset) or a multiple of 90 deg (a guide along x) are
  written as those exact numbers, as a textbook does; every other constant is a symbol with
  its value.

Known: the constants and the inputs (the angle of a link turned by an input joint at the
ground, the coordinate of an input slider).  Unknowns: the other angles and slider
coordinates.  With F(z, w) = 0 the loop equations (x and y of each loop), z the unknowns
and w the inputs:

    velocity:      A z' = B w',           A = dF/dz,  B = -dF/dw
    acceleration:  A z'' = B w'' + c,     c = -(A' z' - B' w')  (A', B' their time derivatives)

det A vanishes where the inputs lose control of the unknowns (limit positions, dead
centres): its factors are solved for the angles they contain.

sympy is imported inside the functions that use it (about 0.5 s): the other commands do not
pay for it.
"""

from __future__ import annotations


import numpy as np

from ...errors import MechanismFileError, UsageError
from ...model.geometry import wrap_angle as _wrap
from ...model.state import KinematicState
from .cycles import fundamental_cycles
from .det_conditions import determinant
from .placing import LOWER, joint_configuration
from .rolling import (HIGHER, drop_constant_rows, measure_pairs, pair_term, substitute_pairs, turns_through_pairs,
                      unwrapped)
from ..motion.planar import LinkAngles
from .skeleton import numbering
from .symbols import LoopEquation, PlanarEquations, Symbol, Vector
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism

__all__ = ["VectorLoops"]

_SUFFIX = "abcdefghijklmnopqrstuvwxyz"


#: Guard: the characteristic length taken at least this [m] where a length is compared with it.
LENGTH_FLOOR = 1e-9


def _exact_angle(sp, value: float | np.ndarray, tol: float):
    """An exact multiple of pi/2 when ``value`` is one (within tol [rad]: the closure tolerance,
    to which the configuration measured is closed), else None."""
    k = round(value / (np.pi / 2))
    if abs(value - k * np.pi / 2) < tol:
        return sp.Integer(k) * sp.pi / 2
    return None


class VectorLoops:
    """The loop equations of a planar mechanism of revolute and prismatic joints and rolling and
    gear pairs, built at an assembled configuration q (where every constant is measured), for the given input
    joints.  Holds the sympy expressions and their numerical forms; ``result()`` gives the
    plain :class:`PlanarEquations`."""

    def __init__(self, mech: Mechanism, q: np.ndarray, inputs: list | None=None, links: list | tuple=()) -> None:
        """Every command that writes these equations (equations, solve --start, singularities
        --symbolic, report) builds them here: rolling and gear pairs included.  ``links``: links
        whose absolute angle is an input too (--set-angle of a floating link): their theta is known."""
        import sympy as sp

        self.sp = sp
        self.mech = mech
        self.q = np.array(q, float)
        topo = mech.topology(q)
        self.topo = topo
        self.tree = {j.name: j for j in topo.joints if not j.cut}
        path = mech.path
        if topo.motion_space != "planar":
            raise UsageError(f"{path}: the vector-loop equations are for planar mechanisms; this one is "
                             f"{topo.motion_space}")
        other = [j for j in topo.joints if j.type not in LOWER and j.type not in HIGHER]
        if other:
            j = other[0]
            raise MechanismFileError(path, f"the vector-loop equations take revolute and prismatic joints, rolling "
                                           f"and gear pairs; "
                                           f"'{j.name}' is a {j.type} pair (screwkin screws gives the "
                                           "product-of-exponentials structure equations)")
        if topo.couplings:
            raise MechanismFileError(path, "the vector-loop equations do not take <mimic> couplings "
                                           f"('{topo.couplings[0].joint}')")
        if topo.loops < 1:
            raise UsageError(f"{path}: the mechanism has no loops: there is no loop equation to write "
                             "(screwkin screws --output LINK gives a chain's structure equations)")
        self.input_links = list(links)
        self.inputs_joints = list(inputs) if inputs or self.input_links else list(mech.actuated)
        if not self.inputs_joints and not self.input_links:
            raise UsageError(f"{path}: no input joints: declare actuated joints or give --input NAME")
        for n in self.inputs_joints:
            mech.coordinate(n)  # an unknown name is a one-line UsageError
        self.angles = LinkAngles(mech, topo)
        self.e1, self.e2, self.n = self.angles.e1, self.angles.e2, self.angles.n
        # the one link numbering of screwkin (draw, report, equations): ground 1, then along the chain from the input
        self.numbers = dict(numbering(topo, self.inputs_joints)[0])
        self._build_classes()
        self._measure()
        self._build_loops()
        self._build_inputs()
        self._build_matrices()

    # ------------------------------------------------------------------ geometry
    @staticmethod
    def wrap(a: float | np.ndarray) -> float | np.ndarray:
        return _wrap(a)

    def exact_angle(self, value):
        """An exact multiple of pi/2 (sympy) when ``value`` [rad] is one, else None."""
        return _exact_angle(self.sp, value, self.mech.tolerances.closure)

    def constants_now(self) -> dict:
        """The constant symbols made so far -> their values (the loops are still being built)."""
        return {self.sym[n]: s.value for n, s in self.symbol_info.items() if s.role == "constant"}

    def _p2(self, v: np.ndarray | tuple) -> np.ndarray:
        v = np.asarray(v, float)
        return np.array([v @ self.e1, v @ self.e2])

    def _build_classes(self) -> None:
        """Links joined by prismatic joints turn together: one angle per class."""
        topo = self.topo
        parent = {lk: lk for lk in topo.links}

        def find(x):
            while parent[x] != x:
                x = parent[x]
            return x

        for j in topo.joints:
            if j.type == "prismatic":
                a, b = find(j.links[0]), find(j.links[1])
                if a != b:
                    parent[b] = a
        classes = {}
        for lk in topo.links:
            classes.setdefault(find(lk), []).append(lk)
        self.rep = {}
        for members in classes.values():
            r = topo.ground if topo.ground in members else min(members, key=lambda m: self.numbers[m])
            for m in members:
                self.rep[m] = r

    def _measure(self) -> None:
        """World positions of the joint centres at q; the anchors (points fixed in a link) of
        each joint on each of its links, as (frame id, local point) for forward kinematics."""
        mech, topo = self.mech, self.topo
        self.state = state = KinematicState(mech, self.q)  # the configuration the equations are built at
        self.theta_q = self.angles(self.q, state)
        self.frames = {lk: mech.link_frame(lk) for lk in topo.links}
        self.anchor = {}  # (joint, link) -> 2D point at q
        self.local = {}  # (joint, link) -> (frame id, local 3D point)
        self.slides = {}  # prismatic joint name -> dict

        def first_revolute(link: str, skip):
            for j in topo.joints:
                if j is not skip and link in j.links and j.type in ("revolute", "continuous"):
                    return j
            return None

        def keep(key, link: str, point) -> None:
            fid = self.frames[link]
            self.anchor[key] = self._p2(point)
            self.local[key] = (fid, state.frame_placement(fid).actInv(np.asarray(point, float)))

        self.keep = keep

        for j in topo.joints:
            if j.type in ("revolute", "continuous"):
                for lk in j.links:
                    keep((j.name, lk), lk, j.point)
        for j in topo.joints:
            if j.type != "prismatic":
                continue
            g, s = j.links
            ja, jb = first_revolute(g, j), first_revolute(s, j)
            A = np.asarray(ja.point if ja is not None else j.point, float)
            B = np.asarray(jb.point if jb is not None else j.point, float)
            keep((j.name, g), g, A)
            keep((j.name, s), s, B)
            u3 = np.asarray(j.direction, float)
            u = self._p2(u3)
            u /= np.linalg.norm(u)
            d = self._p2(B - A)
            flip = -1.0 if d @ u < 0 else 1.0
            u = flip * u
            nrm = np.array([-u[1], u[0]])
            fid = self.frames[g]
            u_local = state.frame_placement(fid).rotation.T @ (flip * u3 / np.linalg.norm(self._p2(u3)))
            self.slides[j.name] = {"guide": g, "slider": s, "u": u, "x": float(d @ u), "e": float(d @ nrm),
                                   "u_local": u_local, "from": ja.name if ja is not None else j.name,
                                   "to": jb.name if jb is not None else j.name}
        self.pair_geometry = measure_pairs(self, state)  # rolling and gear pairs: their centres, radii

    # ------------------------------------------------------------------ symbols
    def _new_symbol(self, name: str, link: str, kind: str, value: float | np.ndarray, role: str, meaning: str):
        sym = self.sp.Symbol(name, real=True)
        self.symbol_info[name] = Symbol(name, link, kind, float(value), role, meaning)
        self.sym[name] = sym
        return sym

    def _theta(self, link: str):
        """The angle symbol of a moving class (created on first use)."""
        r = self.rep[link]
        name = f"theta{self.numbers[r]}"
        if name not in self.sym:
            a, b = self.angles.along().get(r, ("", ""))
            line = f"the line {a} to {b} on it" if b != "x axis" else "its frame's x axis"
            self._new_symbol(name, r, "angle", self.theta_q[r], "unknown",
                             f"absolute angle of link '{r}' (its link_angles value: {line})" if a else
                             f"absolute angle of link '{r}' (its link_angles value)")
            self.variables.append(name)
        return self.sym[name]

    def _suffix(self, k: int, used: dict) -> str:
        n = used.get(k, 0)
        used[k] = n + 1
        return "" if n == 0 else _SUFFIX[n]

    def _constant_angle(self, name: str, link: str, value: float, meaning: str):
        exact = _exact_angle(self.sp, value, self.mech.tolerances.closure)
        if exact is not None:
            return exact
        return self._new_symbol(name, link, "angle", value, "constant", meaning)

    def _vector(self, link: str, ka: tuple, kb: tuple) -> tuple | None:
        """(vector record, sign) for the vector on ``link`` from anchor ka to anchor kb, or None
        when the two centres coincide."""
        sp = self.sp
        key = (link, frozenset((ka, kb)))
        if key in self.vec:
            v = self.vec[key]
            return (v, 1) if v["from"] == ka else (v, -1)
        d = self.anchor[kb] - self.anchor[ka]
        length = float(np.linalg.norm(d))
        tol = self.mech.tolerances
        # centres closer than the geometric tolerance are one point (the loop closes them only to its
        # tolerance, 5e-11 m on the corpus five-bar's 'sphere'): no vector, and no angle of a link that
        # has no other vector -- it would be one more unknown than the loop has equations
        if length < tol.geometry * max(self.mech.length, 1.0):
            return None
        phi = float(np.arctan2(d[1], d[0]))
        k = self.numbers[link]
        suffix = self._suffix(k, self.used_r)
        name = f"r{k}{suffix}"
        start, end, sign = ka, kb, 1
        rep = self.rep[link]
        if rep == self.topo.ground:
            if not -np.pi / 2 < phi <= np.pi / 2 + tol.zero:  # ground vectors point to +x, as drawn in books
                start, end, sign, phi = kb, ka, -1, _wrap(phi + np.pi)
            angle = self._constant_angle(f"theta{k}{suffix}", link, phi, f"constant angle of {name} on the ground")
        else:
            alpha = _wrap(phi - self.theta_q[rep])
            if abs(alpha) > np.pi / 2 + tol.zero:
                start, end, sign, alpha = kb, ka, -1, _wrap(alpha + np.pi)
            theta = self._theta(link)
            if abs(alpha) < tol.closure:
                angle = theta
            else:
                exact = _exact_angle(sp, alpha, tol.closure)
                off = exact if exact is not None else self._new_symbol(
                    f"alpha{k}{suffix}", link, "angle", alpha, "constant",
                    f"constant angle of {name} from theta{self.numbers[rep]} (fixed in link '{link}')")
                angle = theta + off
        lsym = self._new_symbol(name, link, "length", length, "constant",
                                f"length of link '{link}' between the centres of {start[0]} and {end[0]}")
        v = {"name": name, "link": link, "from": start, "to": end, "length": lsym, "angle": angle}
        self.vec[key] = v
        return v, sign

    def _slide(self, joint: str) -> dict:
        """The slider term's symbols of a prismatic joint (created on first use)."""
        if joint in self.slide_terms:
            return self.slide_terms[joint]
        sl = self.slides[joint]
        g, s = sl["guide"], sl["slider"]
        k = self.numbers[s]
        suffix = self._suffix(k, self.used_x)
        rep = self.rep[g]
        phi = float(np.arctan2(sl["u"][1], sl["u"][0]))
        if rep == self.topo.ground:
            beta = self._constant_angle(f"beta{k}{suffix}", g, phi,
                                        f"constant angle of the guide of x{k}{suffix} (unit vector u{k}{suffix})")
            angle = beta
        else:
            off = _wrap(phi - self.theta_q[rep])
            theta = self._theta(g)
            if abs(off) < self.mech.tolerances.closure:
                angle = theta
            else:
                exact = _exact_angle(self.sp, off, self.mech.tolerances.closure)
                angle = theta + (exact if exact is not None else self._new_symbol(
                    f"beta{k}{suffix}", g, "angle", off, "constant",
                    f"constant angle of the guide of x{k}{suffix} from theta{self.numbers[rep]}"))
        x = self._new_symbol(f"x{k}{suffix}", s, "slider", sl["x"], "unknown",
                             f"slider coordinate of joint '{joint}': from the centre of {sl['from']} along the "
                             f"guide on '{g}' to the centre of {sl['to']} on '{s}'")
        self.variables.append(x.name)
        e = 0
        # an offset below the geometric tolerance is round-off of a loop closed at a double root: zero
        if abs(sl["e"]) > self.mech.tolerances.geometry * max(self.mech.length, 1.0):
            e = self._new_symbol(f"e{k}{suffix}", g, "length", sl["e"], "constant",
                                 f"offset of the centre of {sl['to']} from the guide line of x{k}{suffix} "
                                 f"(along n{k}{suffix}, u{k}{suffix} turned +90 deg)")
        term = {"x": x, "e": e, "angle": angle, "name": f"{k}{suffix}"}
        self.slide_terms[joint] = term
        return term

    def ground_guide(self, x_name: str) -> tuple | None:
        """(beta, e) of the slider coordinate ``x_name`` when its guide is on the ground: the
        guide's constant angle from the ground's x axis [rad] and the offset of the slider's
        centre from the guide line [m] (the slider's centre is at from + x u + e n); None for a
        guide on a moving link or an unknown name."""
        for term in self.slide_terms.values():
            if term["x"].name != x_name:
                continue
            angle, e = term["angle"], term["e"]
            if angle.free_symbols - {sym for sym in angle.free_symbols if str(sym).startswith("beta")}:
                return None  # the guide turns with a link
            beta = float(angle.subs({sym: self.symbol_info[str(sym)].value for sym in angle.free_symbols}))
            offset = float(self.symbol_info[str(e)].value) if e != 0 else 0.0
            return beta, offset
        return None

    # ------------------------------------------------------------------ loops
    def _build_loops(self) -> None:
        sp = self.sp
        self.symbol_info, self.sym, self.variables = {}, {}, []
        self.vec, self.slide_terms, self.used_r, self.used_x, self.used_rho = {}, {}, {}, {}, {}
        self.loops, self.F = [], []
        self.pairs, self.pair_notes = [], []
        self.loop_twists = []  # per loop: [(joint, (vx, vy, w))] planar twists, the loop's first joint at 0
        for links, joints in fundamental_cycles(self.topo):
            m = len(links)
            terms, fx, fy = [], sp.Integer(0), sp.Integer(0)
            crossed = []  # (pair record, placeholder symbol) of the rolling pairs crossed
            # the joint closing the walk sits at the loop's origin (a pair's twist is put where the walk crosses it)
            twists = [] if joints[-1].type == "prismatic" or joints[-1].type in HIGHER else \
                [(joints[-1].name, (0, 0, 1))]
            for i in range(m):
                link, j_in, j_out = links[i], joints[i - 1], joints[i]
                got = self._vector(link, (j_in.name, link), (j_out.name, link))
                if got is not None:
                    v, sign = got
                    terms.append(("" if sign > 0 else "-") + v["name"])
                    fx += sign * v["length"] * sp.cos(v["angle"])
                    fy += sign * v["length"] * sp.sin(v["angle"])
                if j_out.type in HIGHER:  # a rolling or gear pair: its no-slip law (analysis.course.rolling)
                    rec = self.pair_geometry[j_out.name]
                    hold = sp.Dummy(f"k_{j_out.name}") if rec["kind"] != "rack" else None
                    px, py, names, pair = pair_term(self, rec, hold)
                    sign = 1 if rec["a"] == link else -1
                    # a revolute at the contact point (the instantaneous centre of rolling without slip); a
                    # rack's from the pinion's centre, reached by the loop's own vectors (the rest of the loop
                    # walked back when the walk crosses from the rack: put in below)
                    if rec["kind"] == "rack":
                        nx, ny = rec["facing"]
                        twists.append((j_out.name, (fy + ny, -(fx + nx), 1)) if sign < 0 else
                                      (j_out.name, ("after", fx + px, fy + py, nx, ny)))
                    else:
                        ax, ay = (fx, fy) if sign > 0 else (fx - px, fy - py)  # link a's anchor of the pair
                        cx, cy = ax + rec["contact"][0], ay + rec["contact"][1]
                        twists.append((j_out.name, (cy, -cx, 1)))
                    fx += sign * px
                    fy += sign * py
                    terms += [(("" if sign > 0 else "-") + t).replace("--", "") for t in names]
                    crossed.append((rec, hold, pair))
                elif j_out.type == "prismatic":  # crossing it from links[i] to links[i + 1]
                    t = self._slide(j_out.name)
                    sign = 1 if self.slides[j_out.name]["guide"] == link else -1
                    c, s = sp.cos(t["angle"]), sp.sin(t["angle"])
                    twists.append((j_out.name, (c, s, 0)))  # a sliding twist: the guide's direction
                    pre = "" if sign > 0 else "-"
                    terms.append(f"{pre}x{t['name']}*u{t['name']}")
                    fx += sign * (t["x"] * c - t["e"] * s)
                    fy += sign * (t["x"] * s + t["e"] * c)
                    if t["e"] != 0:
                        terms.append(f"{pre}e{t['name']}*n{t['name']}")
                elif i < m - 1:  # a revolute at (fx, fy) from the loop's first joint: (y, -x, 1)
                    twists.append((j_out.name, (fy, -fx, 1)))
            rows = [fx, fy]
            # the pinion's centre after crossing a rack: the loop back from there, -(the rest of the walk)
            twists = [(n, t) if not isinstance(t[0], str) else (n, (t[2] - fy + t[4], -(t[1] - fx + t[3]), 1))
                      for n, t in twists]
            if crossed:
                rows, twists = substitute_pairs(self, len(self.loops) + 1, rows, crossed, twists)
            self.loops.append(LoopEquation(tuple(links), tuple(j.name for j in joints), tuple(terms),
                                           tuple(str(r) for r in rows)))
            self.loop_twists.append(twists)
            self.F += rows

    def _build_inputs(self) -> None:
        """The symbol each input joint sets, and d symbol / d joint value."""
        topo, mech = self.topo, self.mech
        joints = {j.name: j for j in topo.joints}
        self.input_syms, self.input_joints = [], {}
        for name in self.inputs_joints:
            j = joints.get(name)
            if j is None or j.type not in LOWER or j.cut:
                raise UsageError(f"{mech.path}: input '{name}' is not a revolute or prismatic joint of the tree")
            parent, child = j.links
            if j.type == "prismatic":
                t = self._slide(name)
                sl = self.slides[name]
                sigma = float(np.sign(self._p2(j.direction) @ sl["u"]))
                sym = t["x"].name
            else:
                gp, gc = self.rep[parent] == topo.ground, self.rep[child] == topo.ground
                if gp == gc:
                    raise UsageError(f"{mech.path}: input joint '{name}' joins two moving links: its value is a "
                                     "relative angle; the equations take inputs turning a link at the ground "
                                     "(or sliders)")
                moving = child if gp else parent
                sym = self._theta(moving).name
                sigma = float(np.sign(np.asarray(j.direction) @ self.n)) * (1 if gp else -1)
            if sym in self.input_joints:
                raise UsageError(f"{mech.path}: inputs '{self.input_joints[sym][0]}' and '{name}' set the same "
                                 f"quantity {sym}")
            self.input_syms.append(sym)
            self.input_joints[sym] = (name, sigma)
            info = self.symbol_info[sym]
            self.symbol_info[sym] = Symbol(info.name, info.link, info.kind, info.value, "input",
                                           info.meaning + f"; set by the input joint '{name}'")
        for link in self.input_links:  # a link's angle given (--set-angle): its theta is the input itself
            self.angles.check(link)
            sym = f"theta{self.numbers[self.rep[link]]}"
            if sym not in self.sym:
                raise UsageError(f"{mech.path}: link '{link}' is in no loop: its angle is not a quantity of the loop "
                                 "equations")
            if sym in self.input_joints:
                raise UsageError(f"{mech.path}: inputs '{self.input_joints[sym][0]}' and the angle of '{link}' set "
                                 f"the same quantity {sym}")
            self.input_syms.append(sym)
            self.input_joints[sym] = (link, 1.0)
            info = self.symbol_info[sym]
            self.symbol_info[sym] = Symbol(info.name, info.link, info.kind, info.value, "input",
                                           info.meaning + "; given as the link's angle (--set-angle)")
        order = {n: k for k, n in enumerate(self.variables)}
        self.unknowns = sorted((v for v in self.variables if v not in self.input_joints),
                               key=lambda n: (self.numbers[self.symbol_info[n].link], n.startswith("x"), order[n]))

    def _build_matrices(self) -> None:
        sp = self.sp
        if self.pairs:
            drop_constant_rows(self)
        F = sp.Matrix(self.F)
        z = [self.sym[n] for n in self.unknowns]
        w = [self.sym[n] for n in self.input_syms]
        self.Fm = F
        self.Am = F.jacobian(z) if z else sp.zeros(len(self.F), 0)
        self.Bm = -F.jacobian(w) if w else sp.zeros(len(self.F), 0)
        self.constants = {self.sym[n]: s.value for n, s in self.symbol_info.items() if s.role == "constant"}
        args = [z, w]
        self._F = sp.lambdify(args, F.subs(self.constants), "numpy")
        self._A = sp.lambdify(args, self.Am.subs(self.constants), "numpy")
        self._B = sp.lambdify(args, self.Bm.subs(self.constants), "numpy")
        # accelerations: A z'' = B w'' + c
        zd = [sp.Symbol(f"{n}_d", real=True) for n in self.unknowns]
        wd = [sp.Symbol(f"{n}_d", real=True) for n in self.input_syms]

        def dt(M):
            out = sp.zeros(*M.shape)
            for s, sd in zip(z + w, zd + wd):
                out += M.diff(s) * sd
            return out

        c = -(dt(self.Am) * sp.Matrix(zd) - dt(self.Bm) * sp.Matrix(wd)) if z else sp.zeros(len(self.F), 1)
        self.cm = sp.Matrix([sp.expand(e) for e in c])
        self._c = sp.lambdify([z, w, zd, wd], self.cm.subs(self.constants), "numpy")

    # ------------------------------------------------------------------ numbers
    def values(self, q: np.ndarray) -> dict:
        """The variable symbols (angles, slider coordinates) at configuration q, by forward
        kinematics of the anchors (the loops need not close at q)."""
        mech = self.mech
        state = KinematicState(mech, q)
        th = self.angles(q, state)
        out = {}
        for n in self.variables:
            info = self.symbol_info[n]
            if info.kind == "angle":
                out[n] = th[info.link] if not self.pairs else unwrapped(self, info.link, th[info.link], q)
        if self.pairs:  # a link turned through a pair: its turns counted by the pair's virtual joints
            out = turns_through_pairs(self, q, out)
        for joint, t in self.slide_terms.items():
            sl = self.slides[joint]
            g, s = sl["guide"], sl["slider"]
            fa, pa = self.local[(joint, g)]
            fb, pb = self.local[(joint, s)]
            A = state.frame_placement(fa).act(pa)
            B = state.frame_placement(fb).act(pb)
            u3 = state.frame_placement(self.frames[g]).rotation @ sl["u_local"]
            u = self._p2(u3)
            out[t["x"].name] = float(self._p2(B - A) @ (u / np.linalg.norm(u)))
        return out

    def _vectors(self, values: dict) -> tuple:
        z = np.array([values[n] for n in self.unknowns], float)
        w = np.array([values[n] for n in self.input_syms], float)
        return z, w

    def residual(self, values: dict) -> np.ndarray:
        return np.asarray(self._F(*self._vectors(values)), float).reshape(-1)

    def matrices(self, values: dict) -> tuple:
        """A and B evaluated at ``values`` (symbol name -> value)."""
        z, w = self._vectors(values)
        A = np.asarray(self._A(z, w), float).reshape(len(self.F), len(self.unknowns))
        B = np.asarray(self._B(z, w), float).reshape(len(self.F), len(self.input_syms))
        return A, B

    def acceleration_terms(self, values: dict, unknown_rates: np.ndarray, input_rates: list) -> np.ndarray:
        z, w = self._vectors(values)
        return np.asarray(self._c(z, w, np.asarray(unknown_rates, float), np.asarray(input_rates, float)),
                          float).reshape(-1)

    # ------------------------------------------------------------------ determinant
    def determinant(self) -> tuple:
        """(det A simplified, its singular conditions as strings, the same in words):
        screwkin.analysis.course.det_conditions."""
        return determinant(self)

    # ------------------------------------------------------------------ result
    def result(self) -> PlanarEquations:
        values = self.values(self.q)
        A, B = self.matrices(values)
        d, conds, words = self.determinant()
        det_value = rates = None
        if A.shape[0] == A.shape[1] and A.size:
            det_value = float(np.linalg.det(A))
            s = np.linalg.svd(A, compute_uv=False)
            if s[-1] > self.mech.tolerances.equal * s[0]:  # A not singular: sigma_min not zero next to sigma_max
                rates = np.linalg.solve(A, B)
        vectors = tuple(Vector(v["name"], v["link"], v["from"][0], v["to"][0], str(v["length"]), str(v["angle"]))
                        for v in self.vec.values())
        notes = []
        in_loops = {lk for loop in self.loops for lk in loop.links}
        out = [lk for lk in self.topo.links if lk not in in_loops]
        if out:
            notes.append(f"links in no loop (not in the equations): {', '.join(out)}")
        return PlanarEquations(
            self.mech.path, tuple(float(x) for x in self.n), dict(self.numbers), tuple(self.loops), vectors,
            dict(self.symbol_info), tuple(self.input_syms), dict(self.input_joints), tuple(self.unknowns),
            tuple(tuple(str(e) for e in self.Am.row(i)) for i in range(self.Am.shape[0])),
            tuple(tuple(str(e) for e in self.Bm.row(i)) for i in range(self.Bm.shape[0])),
            tuple(str(e) for e in self.cm), None if d is None else str(d), conds, words, A, B, det_value, rates,
            tuple(notes + self.pair_notes), tuple(self.pairs))

    # ------------------------------------------------------------------ configurations
    def configuration(self, values: dict) -> np.ndarray:
        """A joint configuration whose link angles and slider coordinates are ``values``
        (screwkin.analysis.course.placing)."""
        return joint_configuration(self, values)
