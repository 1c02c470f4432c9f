"""The planar four-bar in closed form, for synthesis: positions by circle intersection,
branches, transmission angles, a quick defect analysis, and its description as a file.

The input is the crank A0A turning about A0; the moving pivot B is an intersection of the
circle of radius |AB| about A and the circle of radius |B0B| about B0.  The two
intersections are mirror images across the line A B0; ``sigma`` = +1 when B lies to the
left of A -> B0, -1 to the right.  sigma changes only where A, B, B0 are collinear, which
is where the crank stops and turns back (a limit position of the input): along the crank's
motion it labels the branch, and for a crank that turns fully, the circuit.

The transmission angle mu is the angle at B between the coupler (B -> A) and the rocker
(B -> B0), in [0, pi]; 90 deg transmits force best.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from ....files.description import TargetSpec
from ....files.writer import PlanarJoint, PlanarLink, PlanarLinkage, PlanarLoopJoint
from ....model.geometry import circle_circle, cross2, wrap_angle
from ...motion.transmission import transmission_angle
from ....tolerances import DEFAULT
from .designs import Design, FourBar

__all__ = ["angle", "rotate", "pose_matrix", "branch", "tool_local", "positions",
           "travel_analysis", "fourbar_linkage", "crank_angle", "stored"]

TWO_PI = 2 * math.pi


def angle(v: np.ndarray) -> float:
    return float(math.atan2(v[1], v[0]))


def rotate(theta: float | np.ndarray) -> np.ndarray:
    c, s = math.cos(theta), math.sin(theta)
    return np.array([[c, -s], [s, c]])


def pose_matrix(pose: tuple) -> tuple:
    """(R, p) of a pose (x, y, theta)."""
    return rotate(pose[2]), np.array(pose[:2], float)


def branch(A: np.ndarray, B: np.ndarray, B0: np.ndarray | tuple):
    """sigma: +1 when B lies left of the line A -> B0, -1 right (arrays broadcast)."""
    A, B, B0 = (np.asarray(v, float) for v in (A, B, B0))
    return np.sign(cross2(B0 - A, B - A))


def crank_angle(fb: FourBar) -> float:
    return angle(np.subtract(fb.A, fb.A0))


def tool_local(fb: FourBar) -> tuple[float, float, float]:
    """The tool (guided frame or coupler point) in the coupler's frame: origin A, x axis along
    A -> B: (u, v, gamma)."""
    A, B = np.array(fb.A, float), np.array(fb.B, float)
    t = fb.tool if fb.tool is not None else (*fb.A, 0.0)
    phi = angle(B - A)
    u, v = rotate(-phi) @ (np.array(t[:2], float) - A)
    return float(u), float(v), float(t[2] - phi)


def positions(fb: FourBar, theta: float, sigma: float) -> dict:
    """Closed-form positions at crank angles theta (absolute, array): dict with A, B, the tool
    pose (x, y, angle) arrays, h2 (< 0: not assembled) and mu."""
    theta = np.asarray(theta, float)
    lengths = fb.lengths
    a, b, c = lengths["crank"], lengths["coupler"], lengths["rocker"]
    A0 = np.array(fb.A0, float)
    A = A0 + a * np.stack([np.cos(theta), np.sin(theta)], axis=-1)
    B, h2 = circle_circle(A, b, fb.B0, c, sigma)  # h2 < 0: the circles do not meet
    phi = np.arctan2(B[..., 1] - A[..., 1], B[..., 0] - A[..., 0])
    u, v, gamma = tool_local(fb)
    x = A[..., 0] + u * np.cos(phi) - v * np.sin(phi)
    y = A[..., 1] + u * np.sin(phi) + v * np.cos(phi)
    return {"A": A, "B": B, "x": x, "y": y, "angle": phi + gamma, "h2": h2, "mu": transmission_angle(A, B, fb.B0)}


def travel_analysis(fb: FourBar, thetas: np.ndarray, sigmas: np.ndarray, steps: int = 720, span=None):
    """Closed-form counterpart of the check (screwkin.analysis.design.synthesis.check): from the
    first position (crank angle thetas[0], branch sigmas[0]) the crank turns one way; the
    positions k are reached at travel (sign * (theta_k - theta_0)) mod 2 pi when the branch
    carries on that far (no limit position before) and sigma_k is the branch's.

    span: (low, high) crank travel from the first position that must be covered (function
    generation) instead of a search over both directions.
    Returns dict: direction, travel (per position, None when not reached), defects (list of
    (kind, position index, detail)), mu (min, max) over the motion [rad] or None."""
    thetas = np.asarray(thetas, float)
    sigmas = np.asarray(sigmas, float)
    s1 = sigmas[0]

    def along(direction: float, reach: float) -> tuple:
        t = np.linspace(0.0, reach, max(int(steps * reach / TWO_PI), 2) + 1)
        pos = positions(fb, thetas[0] + direction * t, s1)
        bad = np.nonzero(pos["h2"] < 0)[0]
        limit = float(t[bad[0] - 1]) if len(bad) else None  # travel of the last assembled sample
        return t, pos, limit

    n = len(thetas)
    if span is not None:
        results = {}
        for direction, reach in ((1, span[1]), (-1, -span[0])):
            if reach > 0:
                results[direction] = along(direction, reach)
        travel, defects = [0.0] + [None] * (n - 1), []
        mus = []
        for direction, (t, pos, limit) in results.items():
            end = limit if limit is not None else t[-1]
            mus.append(pos["mu"][: np.searchsorted(t, end, side="right")])
            if limit is not None:
                defects.append(("limit", None, direction * limit))
        for k in range(1, n):
            d = thetas[k] - thetas[0]
            direction = 1 if d >= 0 else -1
            t, pos, limit = results.get(direction, (None, None, None))
            if limit is not None and abs(d) > limit:
                defects.append(("limit", k, direction * limit))
            elif sigmas[k] != s1:
                defects.append(("branch", k, None))
            else:
                travel[k] = float(abs(d))
        mu = np.concatenate(mus) if mus else np.zeros(0)
        return {"direction": 0, "travel": tuple(travel), "defects": defects,
                "mu": (float(mu.min()), float(mu.max())) if mu.size else None}
    best = None
    for direction in (1, -1):
        t, pos, limit = along(direction, TWO_PI)
        reach = limit if limit is not None else TWO_PI
        travel, defects = [0.0], []
        for k in range(1, n):
            d = float(np.mod(direction * (thetas[k] - thetas[0]), TWO_PI))
            if d > reach:
                defects.append(("limit", k, direction * reach))
                travel.append(None)
            elif sigmas[k] != s1 or d == 0.0:
                defects.append(("branch", k, None))
                travel.append(None)
            else:
                travel.append(d)
        got = [x for x in travel if x is not None]
        if got == sorted(got) and len(set(got)) == len(got):
            pass
        else:
            defects.append(("order", None, tuple(int(i) for i in np.argsort([x if x is not None else np.inf
                                                                              for x in travel]))))
        far = max(got)
        mu = pos["mu"][: np.searchsorted(t, far, side="right")]
        score = (len(defects), 0 if not any(k == "order" for k, _, _ in defects) else 1)
        entry = {"direction": direction, "travel": tuple(travel), "defects": defects,
                 "mu": (float(mu.min()), float(mu.max())) if mu.size else None}
        if best is None or score < best[0]:
            best = (score, entry)
    return best[1]


#: The joints fourbar_linkage writes at the four-bar's pivots: the fixed pivots A0, B0 and the moving ones A, B.
PIVOT_JOINTS = {"A0": "crank_joint", "A": "coupler_joint", "B": "coupler_rocker", "B0": "rocker_joint"}


def fourbar_linkage(fb: FourBar, name: str, comment: str = "", tool: str | None = "coupler_frame") -> PlanarLinkage:
    """The file description of a four-bar drawn at its first position: links ground, crank,
    coupler, rocker (and ``tool``, a frame welded to the coupler at fb.tool), joints
    crank_joint (actuated), coupler_joint, rocker_joint, the loop joint coupler_rocker at B."""
    A0, A, B, B0 = (np.array(p, float) for p in (fb.A0, fb.A, fb.B, fb.B0))
    L = fb.lengths
    tc, tab, tr = angle(A - A0), angle(B - A), angle(B - B0)
    u, v, gamma = tool_local(fb)
    coupler_points = [(0.0, 0.0), (L["coupler"], 0.0)]
    if tool and fb.tool is not None and math.hypot(u, v) > DEFAULT.equal * max(L.values()) \
            and math.hypot(u - L["coupler"], v) > DEFAULT.equal * max(L.values()):
        coupler_points.append((u, v))
    links = [PlanarLink("ground", (tuple(A0), tuple(B0))),
             PlanarLink("crank", ((0.0, 0.0), (L["crank"], 0.0))),
             PlanarLink("coupler", tuple(coupler_points)),
             PlanarLink("rocker", ((0.0, 0.0), (L["rocker"], 0.0)))]
    joints = [PlanarJoint("crank_joint", "revolute", "ground", "crank", tuple(A0), tc),
              PlanarJoint("coupler_joint", "revolute", "crank", "coupler", (L["crank"], 0.0),
                          wrap_angle(tab - tc, upper=True)),
              PlanarJoint("rocker_joint", "revolute", "ground", "rocker", tuple(B0), tr)]
    if tool and fb.tool is not None:
        links.append(PlanarLink(tool, ((0.0, 0.0),), frame_only=True))
        joints.append(PlanarJoint(f"{tool}_joint", "fixed", "coupler", tool, (u, v), gamma))
    loop = PlanarLoopJoint("coupler_rocker", "revolute", "coupler", (L["coupler"], 0.0), "rocker", (L["rocker"], 0.0),
                           -tab, -tr)
    return PlanarLinkage(name, tuple(links), tuple(joints), (loop,), ("crank_joint",), comment)


def stored(design: Design, labels: list | None = None) -> Design:
    """``design`` with its targets in its file (``<screwkin:targets>``, files.description.TargetSpec),
    so that ``screwkin draw FILE`` shows them later: a pose or point where it was asked, an angle
    about the output link's fixed pivot B0; ``labels`` (one per target): how each reads as typed
    (default the target's label)."""
    specs = []
    for k, t in enumerate(design.targets):
        if t.kind == "angle":
            xyz, yaw = (float(design.fourbar.B0[0]), float(design.fourbar.B0[1]), 0.0), float(t.value[0])
        else:
            xyz, yaw = (float(t.value[0]), float(t.value[1]), 0.0), (float(t.value[2]) if t.kind == "pose" else None)
        specs.append(TargetSpec(t.kind, design.output_link, design.input_joint, float(t.input), xyz, yaw,
                                labels[k] if labels else t.label))
    return replace(design, linkage=replace(design.linkage, targets=tuple(specs)))
