"""Function generation with a four-bar (Freudenstein).

The crank (input, angle phi) and the rocker (output, angle psi) of a four-bar with ground
d, crank a, coupler b and rocker c, both angles from the ground line taken from the
rocker's pivot B0 = (0, 0) towards the crank's pivot A0 = (d, 0) (the x axis), obey

    K1 cos(phi) - K2 cos(psi) + K3 = cos(phi - psi),
    K1 = d / c,  K2 = d / a,  K3 = (a^2 - b^2 + c^2 + d^2) / (2 a c)

(the coupler's length |B - A| = b with A = (d, 0) + a (cos phi, sin phi), B = c (cos psi,
sin psi)), linear in K.  y = f(x) on [x0, x1] is mapped to phi on the input range and psi
on the output range (phi linear in x, psi linear in y); three precision points give K
exactly (a 3 x 3 linear solve), more give it by least squares.  A negative a or c is a
crank or rocker pointing the other way (its angle + pi).

The structural error is psi generated - psi desired over the range (a dense sample), the
generated psi by circle intersection on the branch of the first precision point.

The function is read by a restricted evaluator (no Python eval): numbers, x, + - * / **,
unary -, the functions sin cos tan exp log sqrt abs and the constants pi and e.
"""

from __future__ import annotations

import ast
import math

import numpy as np

from ....errors import UsageError, quote
from ....model.geometry import circle_circle, wrap_angle
from ....tolerances import DEFAULT
from .designs import Design, FourBar, FunctionResult, SynthesisError, Target
from .fourbar import branch, fourbar_linkage, stored

__all__ = ["parse_function", "precision_points", "freudenstein", "synthesize_function", "function_task",
           "function_result", "FUNCTIONS"]

WHAT = "synthesize function"
FUNCTIONS = {"sin": np.sin, "cos": np.cos, "tan": np.tan, "exp": np.exp, "log": np.log, "sqrt": np.sqrt,
             "abs": np.abs}
CONSTANTS = {"pi": math.pi, "e": math.e}
_BINARY = {ast.Add: np.add, ast.Sub: np.subtract, ast.Mult: np.multiply, ast.Div: np.divide, ast.Pow: np.power}
_MAX_TEXT = 200
_MAX_NODES = 200


def parse_function(text: str):
    """A callable f(x) (numpy arrays) from the text of a function of x, or UsageError."""
    if len(text) > _MAX_TEXT:
        raise UsageError(f"--function: at most {_MAX_TEXT} characters, got {len(text)}")
    try:
        tree = ast.parse(text.strip(), mode="eval")
    except (SyntaxError, ValueError):
        raise UsageError(f"--function: {quote(text)} is not a formula in x (e.g. log(x), x**2, sin(x) + 1)") from None
    nodes = list(ast.walk(tree))
    if len(nodes) > _MAX_NODES:
        raise UsageError(f"--function: the formula is too long ({len(nodes)} parts, at most {_MAX_NODES})")

    def build(node: ast.AST):
        if isinstance(node, ast.Expression):
            return build(node.body)
        if isinstance(node, ast.Constant) and type(node.value) in (int, float):
            v = float(node.value)
            return lambda x: np.full_like(x, v)
        if isinstance(node, ast.Name):
            if node.id == "x":
                return lambda x: x
            if node.id in CONSTANTS:
                v = CONSTANTS[node.id]
                return lambda x: np.full_like(x, v)
            raise UsageError(f"--function: unknown name {quote(node.id, 20)} (use x, pi, e and "
                             f"{', '.join(FUNCTIONS)})")
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.USub, ast.UAdd)):
            f = build(node.operand)
            return (lambda x: -f(x)) if isinstance(node.op, ast.USub) else f
        if isinstance(node, ast.BinOp) and type(node.op) in _BINARY:
            op, f, g = _BINARY[type(node.op)], build(node.left), build(node.right)
            return lambda x: op(f(x), g(x))
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id in FUNCTIONS \
                and len(node.args) == 1 and not node.keywords:
            fn, f = FUNCTIONS[node.func.id], build(node.args[0])
            return lambda x: fn(f(x))
        what = type(node).__name__
        if isinstance(node, ast.Call):
            what = f"call of {quote(ast.unparse(node.func), 20)}"
        raise UsageError(f"--function: {what} is not allowed (numbers, x, + - * / **, "
                         f"{', '.join(FUNCTIONS)}, pi, e)")

    f = build(tree)

    def evaluate(x: np.ndarray) -> np.ndarray:
        with np.errstate(all="ignore"):
            return np.asarray(f(np.asarray(x, float)), float)

    return evaluate


def precision_points(x0: float, x1: float, n: int, spacing: str = "chebyshev") -> np.ndarray:
    """Chebyshev spacing x_j = (x0 + x1)/2 - (x1 - x0)/2 cos((2j - 1) pi / 2n), j = 1..n (the
    nodes that make the largest structural error of an interpolation smallest), or even
    spacing from x0 to x1, ends included."""
    if spacing == "even":
        return np.linspace(x0, x1, n)
    j = np.arange(1, n + 1)
    return (x0 + x1) / 2 - (x1 - x0) / 2 * np.cos((2 * j - 1) * np.pi / (2 * n))


def freudenstein(phi: np.ndarray, psi: np.ndarray) -> tuple:
    """(K1, K2, K3) from the rows [cos phi, -cos psi, 1] K = cos(phi - psi): solved for three
    points, least squares for more."""
    phi, psi = np.asarray(phi, float), np.asarray(psi, float)
    M = np.stack([np.cos(phi), -np.cos(psi), np.ones_like(phi)], axis=1)
    r = np.cos(phi - psi)
    if len(phi) == 3:
        if abs(np.linalg.det(M)) < DEFAULT.zero:
            raise SynthesisError(WHAT, f"the Freudenstein equations of the three precision points are not independent "
                                       f"(determinant {np.linalg.det(M):.2g}): change the ranges or the function (psi "
                                       "= phi + a constant is done by any parallelogram)")
        return tuple(float(k) for k in np.linalg.solve(M, r))
    K, *_ = np.linalg.lstsq(M, r, rcond=None)
    return tuple(float(k) for k in K)


def _generated(K: np.ndarray, d: float, phi: np.ndarray, sigma: float) -> tuple:
    """psi generated at crank angles phi (the crank's own angle offset applied), on branch sigma;
    nan where the linkage does not assemble."""
    K1, K2, K3 = K
    a, c = d / K2, d / K1
    b2 = a * a + c * c + d * d - 2 * a * c * K3
    A = np.array([d, 0.0]) + a * np.stack([np.cos(phi), np.sin(phi)], axis=-1)  # a signed: a reversed crank
    B, h2 = circle_circle(A, math.sqrt(max(b2, 0.0)), (0.0, 0.0), abs(c), sigma)
    psi = np.arctan2(B[..., 1], B[..., 0]) + (math.pi if c < 0 else 0.0)
    return np.where(h2 >= 0, psi, np.nan), A, B


def function_task(text: str, x_range: tuple[float, float], input_range: tuple[float, float], output_range: tuple[float, float], points: int = 3, spacing: str = "chebyshev",
                  ground: float = 0.1, samples: int = 721) -> dict:
    """The task of function generation, checked: the function, its ranges, the precision points
    ``xs`` and their crank and rocker angles ``phi``, ``psi`` [rad], a dense ``sample`` of x with the
    angles there (``phi_sample``, ``psi_sample``)."""
    f = parse_function(text)
    x0, x1 = map(float, x_range)
    if not x1 > x0:
        raise UsageError(f"--x-range: the end must be above the start, got {x0:g}:{x1:g}")
    (p0, p1), (s0, s1) = map(float, input_range), map(float, output_range)
    if p0 == p1 or s0 == s1:
        raise UsageError("--input-range and --output-range must not be empty (A:B with A != B)")
    if abs(p1 - p0) >= 2 * math.pi or abs(s1 - s0) >= 2 * math.pi:
        raise UsageError("--input-range and --output-range must each span less than a turn")
    if points < 3:
        raise UsageError(f"--points: at least 3 precision points, got {points}")
    if spacing not in ("chebyshev", "even"):
        raise UsageError(f"--spacing: chebyshev or even, got {quote(spacing)}")
    if not ground > 0:
        raise UsageError("--ground must be a positive length")
    xs = precision_points(x0, x1, points, spacing)
    sample = np.linspace(x0, x1, samples)
    y_ends = f(np.array([x0, x1]))
    ys, y_sample = f(xs), f(sample)
    if not (np.all(np.isfinite(y_ends)) and np.all(np.isfinite(ys)) and np.all(np.isfinite(y_sample))):
        bad = sample[~np.isfinite(y_sample)]
        where = f" (at x = {bad[0]:.6g})" if len(bad) else ""
        raise UsageError(f"--function {quote(text)} is not finite on [{x0:g}, {x1:g}]{where}")
    if y_ends[1] == y_ends[0]:
        raise UsageError(f"--function {quote(text)} has the same value at both ends of the range: the output "
                         "range cannot be mapped onto it")

    def phi_of(x: float | np.ndarray):
        return p0 + (np.asarray(x) - x0) / (x1 - x0) * (p1 - p0)

    def psi_of(y: float | np.ndarray):
        return s0 + (np.asarray(y) - y_ends[0]) / (y_ends[1] - y_ends[0]) * (s1 - s0)

    return {"text": text, "x0": x0, "x1": x1, "p0": p0, "p1": p1, "s0": s0, "s1": s1, "points": points,
            "spacing": spacing, "ground": ground, "xs": xs, "phi": phi_of(xs), "psi": psi_of(ys), "sample": sample,
            "phi_sample": phi_of(sample), "psi_sample": psi_of(y_sample)}


def synthesize_function(text: str, x_range: tuple[float, float], input_range: tuple[float, float], output_range: tuple[float, float], points: int = 3, spacing: str = "chebyshev",
                        ground: float = 0.1, samples: int = 721) -> FunctionResult:
    """A four-bar whose rocker angle psi follows f(x) while the crank turns through the input
    range: the Freudenstein coefficients through ``points`` precision points, the link lengths
    for a ground of ``ground`` m, the structural error over the range and the design (drawn at
    the first precision point)."""
    task = function_task(text, x_range, input_range, output_range, points, spacing, ground, samples)
    return function_result(task, freudenstein(task["phi"], task["psi"]))


def function_result(task: dict, K: np.ndarray | tuple, d: float | None = None, sigma: float | None = None, offset: tuple = (0.0, 0.0),
                    search=None) -> FunctionResult:
    """The FunctionResult of the four-bar with Freudenstein coefficients K and ground ``d`` (default the
    task's), on branch ``sigma`` (default: the branch nearest the first precision point), its rocker's
    pivot B0 at ``offset`` [m]."""
    text, x0, x1, p0, p1, s0, s1 = (task[k] for k in ("text", "x0", "x1", "p0", "p1", "s0", "s1"))
    points, spacing, xs, phi, psi, sample = (task[k] for k in ("points", "spacing", "xs", "phi", "psi", "sample"))
    ground = task["ground"] if d is None else d
    K1, K2, K3 = K
    if abs(K1) < DEFAULT.equal or abs(K2) < DEFAULT.equal:
        raise SynthesisError(WHAT, f"Freudenstein gives K1 = {K1:.3g}, K2 = {K2:.3g}: a link of infinite length; "
                                   "change the ranges or the precision points")
    d = ground
    a, c = d / K2, d / K1
    b2 = a * a + c * c + d * d - 2 * a * c * K3
    if b2 <= 0:
        raise SynthesisError(WHAT, f"Freudenstein gives K = ({K1:.6g}, {K2:.6g}, {K3:.6g}): the coupler's squared "
                                   f"length {b2:.3g} is not positive, no four-bar; change the ranges")
    b = math.sqrt(b2)
    A0, B0 = np.array([d, 0.0]), np.zeros(2)
    A1 = A0 + a * np.array([math.cos(phi[0]), math.sin(phi[0])])
    B1 = B0 + c * np.array([math.cos(psi[0]), math.sin(psi[0])])
    if sigma is not None or not np.isclose(np.hypot(*(B1 - A1)), b, rtol=1e-9, atol=0):  # the first point on the circle
        sigma1, best = None, 0.0
        for sg in (1.0, -1.0) if sigma is None else (sigma,):
            g, _, _ = _generated(K, d, phi[:1], sg)
            if np.isfinite(g[0]) and (sigma1 is None or abs(wrap_angle(g[0] - psi[0], upper=True))
                                      < abs(wrap_angle(best - psi[0], upper=True))):
                sigma1, best = sg, g[0]
        if sigma1 is None:
            raise SynthesisError(WHAT, "the least-squares four-bar does not assemble at the first precision point")
        _, A, B = _generated(K, d, phi[:1], sigma1)
        A1, B1 = A[0], B[0]
    sigma1 = float(branch(A1, B1, B0))
    gen, _, _ = _generated(K, d, task["phi_sample"], sigma1)
    err = wrap_angle(gen - task["psi_sample"], upper=True)
    err_points = wrap_angle(_generated(K, d, phi, sigma1)[0] - psi, upper=True)
    o = np.asarray(offset, float)  # the whole linkage moved: the angles, measured from the x axis, stay
    fb = FourBar(tuple(map(float, A0 + o)), tuple(map(float, A1 + o)), tuple(map(float, B1 + o)),
                 tuple(map(float, B0 + o)), None)
    L = fb.lengths
    comment = (f"Four-bar synthesized by screwkin for function generation (Freudenstein): the rocker's angle psi "
               f"follows\ny = {text} for x in [{x0:.9g}, {x1:.9g}] while the crank's angle phi runs through "
               f"[{math.degrees(p0):.9g}, {math.degrees(p1):.9g}] deg,\npsi through [{math.degrees(s0):.9g}, "
               f"{math.degrees(s1):.9g}] deg (both from the x axis: from the rocker's pivot rocker_joint to the crank's crank_joint).\n"
               f"{points} precision points ({spacing} spacing): x = " + ", ".join(f"{x:.9g}" for x in xs)
               + f".\nK1 = {K1:.12g}, K2 = {K2:.12g}, K3 = {K3:.12g}; lengths [m]: ground {L['ground']:.9g}, "
               f"crank {L['crank']:.9g}, coupler {L['coupler']:.9g}, rocker {L['rocker']:.9g}.\n"
               "Drawn closed at the first precision point; actuated: crank_joint (input), output: rocker.")
    linkage = fourbar_linkage(fb, "synthesized_function", comment, tool=None)
    rocker_offset = math.pi if c < 0 else 0.0
    targets = tuple(Target("angle", (float(wrap_angle(ps + rocker_offset, upper=True)),), float(ph - phi[0]),
                           f"point {k + 1} (x = {x:.6g})")
                    for k, (x, ph, ps) in enumerate(zip(xs, phi, psi)))
    lo, hi = sorted((p0 - phi[0], p1 - phi[0]))
    labels = [f"x = {x:.5g}: phi {math.degrees(ph):.5g} deg, psi {math.degrees(ps):.5g} deg"  # as typed
              for x, ph, ps in zip(xs, phi, psi)]
    design = stored(Design("function", fb, linkage, targets, "crank_joint", "rocker", (float(lo), float(hi)),
                           exact=points == 3, input_offset=float(phi[0])), labels)
    defects = []
    if not np.all(np.isfinite(gen)):
        defects.append("the linkage does not assemble over the whole input range (a limit position inside it)")
    sig = [float(branch(A0 + a * np.array([math.cos(p), math.sin(p)]),
                        B0 + c * np.array([math.cos(s), math.sin(s)]), B0)) for p, s in zip(phi, psi)]
    if len(phi) == 3 and len(set(sig)) > 1:
        defects.append("branch defect: the precision points lie on different assembly modes")
    return FunctionResult(text, (x0, x1), (p0, p1), (s0, s1), spacing, tuple(map(float, xs)), tuple(map(float, phi)),
                          tuple(map(float, psi)), K, points > 3, sample, err, tuple(map(float, err_points)), design,
                          tuple(defects), search)
