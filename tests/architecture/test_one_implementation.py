"""One implementation, found by reading the source (issue 37): where a concept is written once, a walk over
screwkin/ finds it nowhere else -- the continuation's tangent and jump test (analysis/motion/continuation.py), the
JSON writer (present/jsonout.py), Pinocchio's kinematics read through a KinematicState (model/state.py), and a
unit read once where its value is parsed (units.py).  Each names the places to fold into the one when it fails.
Their behaviour is tested beside their modules (tests/analysis/motion/test_continuation.py,
tests/present/test_json_writer.py, tests/model/test_state_shared.py, tests/test_quantity.py)."""

from __future__ import annotations

import ast
import re
from pathlib import Path

import screwkin

ROOT = Path(__file__).resolve().parents[2]


def test_the_tangent_and_the_jump_test_are_defined_in_one_place():
    """No module but continuation.py defines a tangent, a jump test, a branch rule or a limit locator of
    the continuation by name; the engines subclass or call it.  Allowed: the homotopy trackers' own
    tangent coordinates (model/homotopy/square.py, model/kernel/algebraic.py: the certified mode search's charts, a
    different space), BatchedCurve.tangents (Curve's on stacks, calling projections), and sweep's
    _start_tangent (Curve.tangent, oriented along the grid); model/distances.py's tangent (the platform
    homotopy's chart: a pose's translation and quaternion, the space of model/homotopy/square.py's); and the singular
    locus's tangent (analysis/singularities/loci.py: the null vector of the augmented system [closure;
    A v = 0; |v| = 1], another curve than an input's motion, oriented by continuation.orient)."""
    allowed = {("model/homotopy/square.py", "tangent"), ("model/kernel/algebraic.py", "tangent"), ("model/distances.py", "tangent"),
               ("model/homotopy/monodromy.py", "tangent"),  # the Closure protocol: those charts' tangent, declared
               ("analysis/singularities/loci.py", "tangent"),
               ("analysis/motion/batch_sweep.py", "tangents"), ("analysis/motion/sweep.py", "_start_tangent")}
    words = ("tangent", "jump", "orient", "passes_limit", "on_arc", "brentq")
    found = []
    package = ROOT / "screwkin"
    for path in sorted(package.rglob("*.py")):
        rel = path.relative_to(package).as_posix()
        if rel == "analysis/motion/continuation.py":
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, (ast.FunctionDef, ast.ClassDef)) and any(w in node.name for w in words[:-1]) \
                    and (rel, node.name) not in allowed and not node.name.startswith("_orientation"):
                found.append(f"{rel}: {node.name}")
    assert not found, found
    # every Brent's method of the continuation goes through continuation.locate
    for rel in ("analysis/motion/sweep.py", "analysis/motion/tracker.py", "analysis/motion/dyads.py",
                "analysis/motion/batch_sweep.py"):
        assert "brentq" not in (package / rel).read_text(), rel
    # the private tracker is gone
    assert "_Tracker" not in (package / "analysis/motion/sweep.py").read_text()


def test_no_module_but_the_writer_writes_json():
    """json.dumps and json.dump are called in present/jsonout.py alone: a newcomer who changes how JSON
    is written finds one place."""
    # files/generic_cache.py stores screwkin's own numbers (a generic solution set and its digest) for
    # screwkin to read back, not an answer for a person: it is a file format of the files/ layer, which
    # cannot import present/
    own = {"screwkin/present/jsonout.py", "screwkin/files/generic_cache.py"}
    found = []
    for path in sorted((ROOT / "screwkin").rglob("*.py")):
        if path.relative_to(ROOT).as_posix() in own:
            continue
        for k, line in enumerate(path.read_text().splitlines(), 1):
            if re.search(r"\bjson\.dumps?\(", line):
                found.append(f"{path.relative_to(ROOT)}:{k}")
    assert not found, found


#: The modules that may call Pinocchio's kinematics themselves, by the rule of model/state.py's docstring:
#: an algorithm's inner loop on a Data it keeps, a stack of configurations at once, a dynamics algorithm.
PINOCCHIO_KINEMATICS = {
    "model/state.py": "the state itself",
    "model/_pin.py": "the shape-fixing wrappers of Pinocchio's calls",
    "model/kernel/closure.py": "the closure's residual and Jacobian (the Newton loops' inner loop)",
    "model/kernel/contacts.py": "the sliding contacts' rows of the closure, in the closure's own Data",
    "model/kernel/wrenches.py": "each closure row's constraint wrench, in the closure's own Data",
    "analysis/position/position.py": "the position solver's mode signature, at every start",
    "analysis/motion/links.py": "frame motions of a stack of configurations (Pinocchio a step)",
    "model/kernel/stacks.py": "batched kinematics and closure, their self-checks against Pinocchio",
    "analysis/singularities/batch.py": "frame Jacobians of a stack of configurations",
    "analysis/forces/dynamics.py": "the energies' own pass (CRBA, the potential energy with couplings)",
    "model/kernel/algebraic.py": "the polynomial closure's reference placements and leg lengths, on a bare model",
    "model/legs.py": "which legs are distances, probed on a bare model's joint centres",
}


def test_only_the_named_rooms_call_pinocchios_kinematics():
    """Whatever reads one configuration's quantities reads a KinematicState (model/state.py's rule)."""
    root = Path(screwkin.__file__).parent
    calls = re.compile(r"framesForwardKinematics|forwardKinematics\(|updateFramePlacements|computeJointJacobians?\("
                       r"|computeFrameJacobian|getFrameJacobian|getFrameVelocity|getFrameClassicalAcceleration"
                       r"|\.oMf\[|\.oMi\[")
    found = {p.relative_to(root).as_posix() for p in root.rglob("*.py") if calls.search(p.read_text())}
    outside = sorted(found - set(PINOCCHIO_KINEMATICS))
    assert not outside, f"forward kinematics outside the state (read a KinematicState): {outside}"


def test_no_module_reads_a_unit_again_after_parsing():
    """The unit of a value is read where the value is parsed (units.parse_quantity, through the
    commands' joint_quantities and joint_value): no module asks units.py for the unit of a text again,
    and none holds a table of unit factors or display units of its own."""
    found = []
    for path in sorted((ROOT / "screwkin").rglob("*.py")):
        rel = path.relative_to(ROOT).as_posix()
        if rel == "screwkin/units.py":
            continue
        text = path.read_text()
        for pattern in (r"\bparse_typed_value\b", r"\bunit_kind\(", r"\bUNITS\[", r"_RATE = \{", r"_ACCEL = \{",
                        r"_LENGTH_UNITS\b"):
            if re.search(pattern, text):
                found.append(f"{rel}: {pattern}")
    assert not found, found
