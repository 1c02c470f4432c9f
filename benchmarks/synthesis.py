"""Path synthesis against pylinkage's optimizer, in one run: the error each reaches through the same
target points, and the time it takes (the machines are shared: read the ratios).

    python benchmarks/synthesis.py [--points 5] [--particles 100] [--iterations 200]

The targets are points of a coupler curve of a crank-rocker chosen by hand (ground pivots A0 = (0, 0),
B0 = (0.09, 0.02) m; crank 35, coupler 110, rocker 75 mm; the coupler point (40, 25) mm off the
crank's end, in the coupler's frame), at crank angles spread over 300 deg: an exact solution exists.

- pylinkage 1.3 ``particle_swarm_optimization`` (its ring-topology PSO in numpy, 100 particles, 200
  iterations) over the constraints of its linkage (the crank's radius, the dyad's two distances, the
  coupler point's distance and angle: its API cannot move ground pivots, so they are given the true
  ones, an advantage), the score the root mean square distance from each target to the nearest of the
  tracer's loci over one crank turn (its ``kinematic_minimization`` simulation, 96 frames);
- ``screwkin.analysis.design.synthesis.optimal.optimal_path``: the pivots free in a box 0.15 m around
  the points, every length free in 5 .. 300 mm (no other constraint), in this process; the error is
  the written design's own, by its closed form (the command also checks it with screwkin's solve).

Both errors are measured here by the same function of the result's geometry: the largest distance
from a target to its nearest point of the coupler curve (36,000 crank angles).
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

A0, B0 = np.array([0.0, 0.0]), np.array([0.09, 0.02])
CRANK, COUPLER, ROCKER = 0.035, 0.11, 0.075
POINT = np.array([0.04, 0.025])


def _curve(A0, B0, a, b, c, p, q, sigma, n=36000):
    """The coupler point's curve (N, 2) over a crank turn, on branch sigma (where it assembles)."""
    th = np.linspace(0, 2 * np.pi, n, endpoint=False)
    A = A0 + a * np.stack([np.cos(th), np.sin(th)], -1)
    w = B0 - A
    d = np.hypot(*w.T)
    along = (b * b - c * c + d * d) / (2 * d)
    h2 = b * b - along * along
    u = w / d[:, None]
    nrm = np.stack([-u[:, 1], u[:, 0]], -1)
    B = A + along[:, None] * u + (sigma * np.sqrt(np.maximum(h2, 0)))[:, None] * nrm
    e = (B - A) / b
    f = np.stack([-e[:, 1], e[:, 0]], -1)
    P = A + p * e + q * f
    return P[h2 >= 0]


def targets(count: int):
    th = np.radians(np.linspace(20, 320, count))
    P = []
    for t in th:
        A = A0 + CRANK * np.array([math.cos(t), math.sin(t)])
        w = B0 - A
        d = math.hypot(*w)
        along = (COUPLER ** 2 - ROCKER ** 2 + d * d) / (2 * d)
        h = math.sqrt(COUPLER ** 2 - along ** 2)
        u = w / d
        B = A + along * u + h * np.array([-u[1], u[0]])
        e = (B - A) / COUPLER
        P.append(A + POINT[0] * e + POINT[1] * np.array([-e[1], e[0]]))
    return np.array(P)


def worst_miss(curve, pts) -> float:
    if not len(curve):
        return math.inf
    return float(max(np.min(np.hypot(*(curve - p).T)) for p in pts))


def pylinkage_run(pts, particles: int, iterations: int):
    """(error, seconds, evaluations) of pylinkage's particle swarm on the targets."""
    from pylinkage.actuators import Crank
    from pylinkage.components import Ground
    from pylinkage.dyads import FixedDyad, RRRDyad
    from pylinkage.optimization import particle_swarm_optimization
    from pylinkage.optimization.utils import kinematic_minimization
    from pylinkage.simulation import Linkage

    g1, g2 = Ground(*A0, name="A0"), Ground(*B0, name="B0")
    crank = Crank(anchor=g1, radius=0.05, angular_velocity=2 * np.pi / 96, name="A")
    dyad = RRRDyad(anchor1=crank.output, anchor2=g2, distance1=0.1, distance2=0.08, name="B")
    tracer = FixedDyad(anchor1=crank.output, anchor2=dyad, distance=0.05, angle=0.3, name="P")
    linkage = Linkage([g1, g2, crank, dyad, tracer], name="fourbar")
    evaluations = [0]

    @kinematic_minimization
    def score(linkage, params, init_pos, loci):
        evaluations[0] += 1
        P = np.array([frame[-1] for frame in loci], float)
        return float(np.sqrt(np.mean([np.min(np.sum((P - t) ** 2, axis=1)) for t in pts])))

    # its constraints: the crank's radius, the dyad's two distances, the tracer's distance and angle
    lower = [0.005, 0.005, 0.005, 0.005, -np.pi]
    upper = [0.3, 0.3, 0.3, 0.3, np.pi]
    names = [type(j).__name__ for j in (crank, dyad, tracer)]
    t0 = time.perf_counter()
    best = particle_swarm_optimization(score, linkage, bounds=(lower, upper), n_particles=particles,
                                       iterations=iterations, order_relation=min, verbose=False)
    seconds = time.perf_counter() - t0
    dims = np.asarray(best.dimensions[0], float)
    linkage.set_constraints(dims)
    # its tracer's loci over a fine turn, to measure as screwkin's is measured
    crank.angular_velocity = 2 * np.pi / 36000
    try:
        P = np.array([frame[-1] for frame in linkage.step(iterations=36000)], float)
    except Exception:  # noqa: BLE001 - an unbuildable best
        P = np.zeros((0, 2))
    return worst_miss(P, pts), seconds, evaluations[0], names, dims


def screwkin_run(pts):
    from screwkin.analysis.design.synthesis.constraints import Constraints
    from screwkin.analysis.design.synthesis.fourbar import branch
    from screwkin.analysis.design.synthesis.optimal import optimal_path
    from screwkin.analysis.design.synthesis.search import Search

    centre = pts.mean(axis=0)
    box = (tuple(centre - 0.15), tuple(centre + 0.15))
    t0 = time.perf_counter()
    r = optimal_path([tuple(p) for p in pts], None, Constraints(bounds=box, lengths=(0.005, 0.3)), Search(seed=0))
    seconds = time.perf_counter() - t0
    fb = r.design.fourbar
    L = fb.lengths
    u = np.subtract(fb.B, fb.A) / L["coupler"]
    rel = np.subtract(fb.tool[:2], fb.A)
    p, q = float(rel @ u), float(rel @ np.array([-u[1], u[0]]))
    sigma = float(branch(fb.A, fb.B, fb.B0))
    curve = _curve(np.array(fb.A0), np.array(fb.B0), L["crank"], L["coupler"], L["rocker"], p, q, sigma)
    return worst_miss(curve, pts), seconds, r.search.evaluations, r


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--points", type=int, default=5)
    ap.add_argument("--particles", type=int, default=100)
    ap.add_argument("--iterations", type=int, default=200)
    args = ap.parse_args()
    pts = targets(args.points)
    load = os.getloadavg()[0]
    e_py, t_py, n_py, _, _ = pylinkage_run(pts, args.particles, args.iterations)
    e_sk, t_sk, n_sk, r = screwkin_run(pts)
    print(f"### Path synthesis, {args.points} points of a crank-rocker's coupler curve (load average {load:.1f}, "
          f"{os.cpu_count()} cores)\n")
    print("| tool | largest miss [m] | time [s] | evaluations |")
    print("|---|---|---|---|")
    print(f"| pylinkage 1.3 particle_swarm_optimization ({args.particles} particles x {args.iterations} iterations, "
          f"ground pivots given) | {e_py:.3g} | {t_py:.2f} | {n_py} linkage simulations |")
    print(f"| screwkin optimal_path (4 differential-evolution runs + least squares, pivots free) | {e_sk:.3g} | "
          f"{t_sk:.2f} | {n_sk} population evaluations |")
    print(f"\nscrewkin / pylinkage: time {t_sk / t_py:.2f}, largest miss {e_sk / max(e_py, 1e-300):.2g}")


if __name__ == "__main__":
    main()
