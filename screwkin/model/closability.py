"""Why a mechanism cannot assemble, said in its own lengths: a loop of revolutes with parallel axes (a
four-bar, a planar n-bar) closes only when no side is longer than the others together."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ._pin import joint_axis
from .geometry import cross3
from .state import KinematicState

__all__ = ["closure_obstacle", "closure_gap", "planar_loops", "obstacle_of"]


def planar_loops(mech) -> list:
    """The loops of revolute joints with parallel axes (at the file's configuration) whose sides
    closure_obstacle measures, as structure: [(cut joint name, the links of the sides, the points
    between them)], a point ("frame", id) -- a cut joint's frame F1 first, F2 last -- or ("joint", id),
    a tree joint's centre; with the loop's normal ("frame", F1's id, axis in F1)."""
    model, state = mech.model, KinematicState(mech, mech.neutral())
    out = []
    for c in mech.cuts:
        if c.type not in ("revolute", "continuous") or c.pair:
            continue
        j1, j2 = (model.frames[f].parentJoint for f in (c.frame1, c.frame2))
        s1, s2 = list(model.supports[j1]), list(model.supports[j2])
        common = [j for j in s1 if j in s2]
        path1 = [j for j in reversed(s1) if j not in common]  # from link1's joint towards the root
        path2 = [j for j in s2 if j not in common]  # from the root towards link2's joint
        joints = path1 + path2
        if not joints or any(not model.joints[j].shortname().startswith("JointModelR") for j in joints):
            continue
        axis = state.frame_placement(c.frame1).rotation @ np.asarray(c.axis, float)
        axes = [state.joint_placement(j).rotation @ joint_axis(model.joints[j]) for j in joints]
        if any(np.linalg.norm(cross3(axis, a)) > mech.tolerances.geometry for a in axes):
            continue  # not planar: no side-length test
        points = [("frame", c.frame1)] + [("joint", j) for j in joints] + [("frame", c.frame2)]
        ground = common[-1] if common and common[-1] > 0 else None
        out.append((c.name, _Names(mech, path1, ground, path2), tuple(points),
                    (c.frame1, tuple(np.asarray(c.axis, float)))))
    return out


class _Names:
    """The links of a loop's sides, looked up when first read (a sentence is written only for a loop
    that cannot close)."""

    def __init__(self, mech, path1: list, ground, path2: list) -> None:
        self.mech, self.parts = mech, (path1, ground, path2)
        self._names = None

    def _all(self):
        if self._names is None:
            path1, ground, path2 = self.parts
            links = {}
            for f in self.mech.model.frames:  # the link a tree joint carries: its first body frame
                if f.type == pin.FrameType.BODY:
                    links.setdefault(f.parentJoint, f.name)
            name = lambda j: links.get(j, self.mech.model.names[j])  # noqa: E731
            self._names = tuple([name(j) for j in path1] + [name(ground) if ground is not None else self.mech.spec.root]
                                + [name(j) for j in path2])
        return self._names

    def __iter__(self):
        return iter(self._all())

    def __len__(self) -> int:
        return len(self._all())

    def __getitem__(self, k: int):
        return self._all()[k]


def obstacle_of(cut: str, names: _Names, sides: list, tol: float) -> tuple | None:
    """(why the loop ``cut`` cannot close, by how much its longest side is too long [m]) when its longest
    side (of ``sides``, the lengths of the links ``names``) is longer than the others together (beyond
    ``tol``); None otherwise."""
    longest = int(np.argmax(sides))
    others = sum(sides) - sides[longest]
    if sides[longest] > others + tol:
        rest = " + ".join(nm for k, nm in enumerate(names) if k != longest)
        return (f"loop {cut} cannot close, {names[longest]} {sides[longest]:.6g} m > {rest} = {others:.6g} m (no "
                "side of a closed loop is longer than the others together)", float(sides[longest] - others))
    return None


def closure_gap(mech):
    """(closure_obstacle's sentence, the longest side's excess over the others [m]), or None."""
    state = KinematicState(mech, mech.neutral())
    for cut, names, points, (f1, axis) in planar_loops(mech):
        n = state.frame_placement(f1).rotation @ np.asarray(axis, float)
        n = n / np.linalg.norm(n)

        def flat(ref):
            p = state.centre(ref)
            return p - (p @ n) * n  # noqa: B023 - called within this iteration

        P = [flat(r) for r in points]
        found = obstacle_of(cut, names, [float(np.linalg.norm(P[k + 1] - P[k])) for k in range(len(P) - 1)],
                            mech.tolerances.geometry)
        if found:
            return found
    return None


def closure_obstacle(mech) -> str | None:
    """Why a loop of revolute joints with parallel axes (a four-bar, a planar n-bar) cannot close,
    in its links' lengths: its longest side is longer than the others together ("ground 0.2 m >
    crank + coupler + rocker = 0.18 m"); None when no such loop is found too long.  The sides are
    the distances between consecutive joint axes on each link, fixed by the file."""
    found = closure_gap(mech)
    return found[0] if found else None


