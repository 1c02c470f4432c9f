"""Bertini 2 (pip install bertini2, in a virtual environment of its own) as the outside oracle for the
forward kinematics of a Stewart-Gough platform: Wampler's (1996) formulation in Study's soma
coordinates (e, g) in P^7 -- six leg quadrics and the Study quadric Re(g e') = 0, on a random real
affine patch -- solved by a total-degree homotopy (2^7 = 128 paths).  Usage:

    python bertini_stewart.py GEOMETRY.json [SEED]   # {"base": [[x,y,z]]*6, "platform": [...], "lengths": [...]}

prints one JSON line: the poses (R, t) with e e' away from 0 (the solutions on e e' = 0 are no poses),
distinct, and how many are real.  Derivation: with n = e e', R v = e v e' / n, t = g e' / n (Re(g e') = 0),
each leg |R b + t - a|^2 = L^2 times n is
    g g' + (|a|^2 + |b|^2 - L^2) e e' + 2 Re(e b g') - 2 Re(e b e' a') - 2 Re(g e' a') = 0.
"""

import json
import sys
import time

import numpy as np

import bertini


def qmul(p, q):
    """Hamilton product, (w, x, y, z) order, of two 4-lists (expressions or numbers)."""
    pw, px, py, pz = p
    qw, qx, qy, qz = q
    return [pw * qw - px * qx - py * qy - pz * qz, pw * qx + px * qw + py * qz - pz * qy,
            pw * qy - px * qz + py * qw + pz * qx, pw * qz + px * qy - py * qx + pz * qw]


def conj(p):
    return [p[0], -p[1], -p[2], -p[3]]


def re(p):
    return p[0]


def c(x: float):
    """An exact coefficient node from a float (its shortest decimal: bertini refuses float literals)."""
    return bertini.coefficient(repr(float(x)))


def _form(f):
    """The symmetric 8 x 8 matrix of the quadratic form f(x) (x = (e, g)), by polarization."""
    E = np.eye(8)
    Q = np.zeros((8, 8))
    for j in range(8):
        for k in range(8):
            Q[j, k] = (f(E[j] + E[k]) - f(E[j]) - f(E[k])) / 2
    return Q


def _leg_form(a, b, l):
    aq, bq = [0.0] + list(a), [0.0] + list(b)
    k = a @ a + b @ b - l * l

    def f(x):
        e, g = list(x[:4]), list(x[4:])
        return (g @ np.array(g) + k * (np.array(e) @ e) + 2 * re(qmul(qmul(e, bq), conj(g)))
                - 2 * re(qmul(qmul(qmul(e, bq), conj(e)), conj(aq))) - 2 * re(qmul(qmul(g, conj(e)), conj(aq))))
    return _form(f)


def main(path, seed=7):
    g_ = json.load(open(path))
    print(json.dumps(solve_geometry(np.array(g_["base"], float), np.array(g_["platform"], float),
                                    np.array(g_["lengths"], float), int(seed))))


def solve_geometry(A, B, L, seed: int = 7) -> dict:
    """Bertini's poses of the platform with ground points A, platform points B, leg lengths L."""
    names = [f"e{k}" for k in range(4)] + [f"g{k}" for k in range(4)]
    v = bertini.variables(names)
    sysm = bertini.System()
    sysm.add_variable_group(bertini.VariableGroup(v))  # affine, with a random patch (hom. groups: no start system)
    forms = [_leg_form(a, b, l) for a, b, l in zip(A, B, L)] + [_form(lambda x: re(qmul(x[4:], conj(x[:4]))))]
    for Q in forms:  # each quadric from its symmetric matrix: only nonzero, exact coefficients
        f = None
        for j in range(8):
            for k in range(j, 8):
                q = Q[j, k] * (1 if j == k else 2)
                if abs(q) > 1e-14:
                    term = c(q) * v[j] * v[k]
                    f = term if f is None else f + term
        sysm.add_function(f)
    patch = np.random.default_rng(5).normal(size=8)
    f = None
    for j in range(8):
        term = c(patch[j]) * v[j]
        f = term if f is None else f + term
    sysm.add_function(f - bertini.coefficient("1"))
    t0 = time.time()
    res = bertini.solve(sysm, seed=seed, show_progress=False)
    seconds = time.time() - t0
    poses = []
    for s in res.solutions:
        x = np.array([complex(c) for c in np.asarray(s.point if hasattr(s, "point") else s).ravel()])[:8]
        e_, g_v = x[:4], x[4:]
        n = e_ @ e_
        if abs(n) < 1e-8 * (np.abs(x) @ np.abs(x)):
            continue
        e_ = e_ / np.sqrt(n)
        g_v = g_v / np.sqrt(n)
        w, xq, yq, zq = e_
        R = np.array([[w*w + xq*xq - yq*yq - zq*zq, 2*(xq*yq - w*zq), 2*(xq*zq + w*yq)],
                      [2*(xq*yq + w*zq), w*w - xq*xq + yq*yq - zq*zq, 2*(yq*zq - w*xq)],
                      [2*(xq*zq - w*yq), 2*(yq*zq + w*xq), w*w - xq*xq - yq*yq + zq*zq]])
        tq = qmul(list(g_v), conj(list(e_)))
        t = np.array(tq[1:])
        if any(np.abs(R - P[0]).max() < 1e-6 and np.abs(t - P[1]).max() < 1e-6 for P in poses):
            continue
        poses.append((R, t))
    real = [P for P in poses if np.abs(P[0].imag).max() < 1e-8 and np.abs(P[1].imag).max() < 1e-8]
    return {"paths": 128, "finite_solutions": len(res.solutions), "poses": len(poses), "real": len(real),
            "seconds": round(seconds, 1), "real_poses": [{"R": P[0].real.tolist(), "t": P[1].real.tolist()} for P in real]}


if __name__ == "__main__":
    main(*sys.argv[1:3])
