"""Extended-URDF YAML sidecars: loops as pairs of frame names, actuated joints, joint
replacements (the form of the public example-parallel-robots collection).

The YAML is untrusted: it is read without aliases (no alias bombs), bounded in size
and nesting, and every field's type is checked before it is used.
"""

from __future__ import annotations

import difflib
from collections.abc import Iterable
from pathlib import Path

import numpy as np

from ..errors import MechanismFileError, quote
from .description import LIMITS, CutJointSpec, MechanismSpec
from .urdf import Problems
from .xmlsafe import load_yaml_text, read_regular_file

__all__ = ["read_yaml_sidecar", "axis_letters"]


_YAML_TYPES = {"6d": "fixed", "3d": "spherical"}


_REPLACEMENTS = "SPHERICAL, FIXED, CARDAN, UJOINT, UJOINT_XY or CARDAN_XY (two different axes of X, Y, Z)"


def _replacement_type(t) -> str | None:
    """The canonical replacement type, or None when unknown (UJOINT letters must be two different axes)."""
    t = t.upper()
    if t in ("SPHERICAL", "FIXED", "CARDAN", "UJOINT"):
        return t
    for prefix in ("UJOINT_", "CARDAN_"):
        if t.startswith(prefix):
            letters = t[len(prefix):]
            if len(letters) == 2 and set(letters) <= set("XYZ") and letters[0] != letters[1]:
                return "UJOINT_" + letters
    return None


def _string_list(content: dict, key: str, problems: Problems, what: str="joint names") -> list | None:
    """content[key] as a list of strings (None when absent), with a problem for anything else."""
    value = content.get(key)
    if value is None:
        return None
    if not isinstance(value, list):
        problems.append(f"{key} must be a list of {what}, got {quote(value)}")
        return []
    out = []
    for k, item in enumerate(value, 1):
        if not isinstance(item, str):
            problems.append(f"{key} entry {k} is {quote(item)}, not a string (write names in quotes)")
            continue
        out.append(item)
    return out


def _load_mapping(yaml_path: Path) -> dict:
    """The sidecar's content: a mapping (empty for an empty file), read bounded and without aliases."""
    raw = read_regular_file(yaml_path, LIMITS.yaml_bytes, "YAML sidecar")
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError:
        raise MechanismFileError(yaml_path, "not a text file (not UTF-8)") from None
    content = load_yaml_text(text, yaml_path)
    if content is None:
        content = {}
    if not isinstance(content, dict):
        raise MechanismFileError(yaml_path, f"expected a mapping with closed_loop, type, name_mot, got {quote(content)}")
    return content


def _unknown_keys(content: dict, problems: Problems) -> list[str]:
    """Notes on the keys that are not the format's (a key that is not a name: a problem)."""
    unknown = []
    known = ("closed_loop", "type", "name_mot", "joint_name", "joint_type")
    for key in content:
        if not isinstance(key, str):
            problems.append(f"a key is {quote(key)}, not a name (known keys: {', '.join(known)})")
            break
        if key not in known:  # ignored, but said: a misspelt closed_loop would silently drop every loop
            close = difflib.get_close_matches(key, known, n=1)
            hint = f"did you mean {quote(close[0])}?" if close else f"known keys: {', '.join(known)}"
            unknown.append(f"unknown key {quote(key, 40)} ({hint})")
    return unknown


def _read_loops(spec: MechanismSpec, content: dict, yaml_path: Path, frame_names: Iterable[str],
                frame_body: dict | None, problems: Problems) -> None:
    """The closed_loop pairs (with their type) as cut joints of ``spec``."""
    pairs = content.get("closed_loop")
    pairs = [] if pairs is None else pairs
    if not isinstance(pairs, list):
        raise MechanismFileError(yaml_path, f"closed_loop must be a list of [frame, frame] pairs, got {quote(pairs)}")
    types = content.get("type")
    types = ["6d"] * len(pairs) if types is None else types
    if not isinstance(types, list):
        raise MechanismFileError(yaml_path, f"type must be a list of '3d' or '6d', got {quote(types)}")
    if len(pairs) > LIMITS.loop_joints:
        raise MechanismFileError(yaml_path, f"closed_loop has {len(pairs)} pairs; screwkin reads at most "
                                            f"{LIMITS.loop_joints} loop joints")
    if len(types) != len(pairs):
        problems.append(f"closed_loop has {len(pairs)} pairs but type has {len(types)} entries")
    frames = set(frame_names)
    frame_body = frame_body or {}
    for k, pair in enumerate(pairs):
        if not (isinstance(pair, list) and len(pair) == 2 and all(isinstance(x, str) for x in pair)):
            problems.append(f"closed_loop entry {k + 1} is not a pair of frame names: {quote(pair)}")
            continue
        a, b = pair
        missing = [f for f in (a, b) if f not in frames]
        for f in missing:
            problems.append(f"closed_loop names frame {quote(f)}, which is not in the URDF")
        if a == b:
            problems.append(f"closed_loop entry {k + 1} pairs frame {quote(a)} with itself")
            continue
        if not missing and frame_body.get(a) is not None and frame_body.get(a) == frame_body.get(b):
            problems.append(f"closed_loop entry {k + 1} pairs frames {quote(a)} and {quote(b)}, which are fixed "
                            "together (on the same body): it closes no loop")
            continue
        ctype = types[k] if k < len(types) else "6d"
        if not isinstance(ctype, str) or ctype.lower() not in _YAML_TYPES:
            problems.append(f"closed_loop type {quote(ctype)} is unknown (known: 3d, 6d)")
            continue
        spec.cut_joints.append(
            CutJointSpec(name=f"{a}~{b}", type=_YAML_TYPES[ctype.lower()], frame1=a, frame2=b, source="yaml")
        )


def _read_actuation(spec: MechanismSpec, content: dict, problems: Problems) -> None:
    """The actuated joints (name_mot) and the joint replacements (joint_name, joint_type) of ``spec``."""
    joint_types = {j.name: j.type for j in spec.joints}
    names = _string_list(content, "name_mot", problems)
    if names is not None:
        for n in names:
            if n not in joint_types:
                problems.append(f"name_mot names joint {quote(n)}, which is not in the URDF")
            elif joint_types[n] == "fixed":
                problems.append(f"name_mot names joint {quote(n)}, which is fixed (a motor drives a moving joint)")
        spec.yaml_actuated = names
    jn = _string_list(content, "joint_name", problems) or []
    jt = _string_list(content, "joint_type", problems, "joint types") or []
    if len(jn) != len(jt):
        problems.append(f"joint_name has {len(jn)} entries but joint_type has {len(jt)}")
    replaced = set()
    for n, t in zip(jn, jt):
        canonical = _replacement_type(t)
        if canonical is None:
            problems.append(f"joint_type {quote(t)} is unknown (known: {_REPLACEMENTS})")
            continue
        if n not in joint_types:
            problems.append(f"joint_name names joint {quote(n)}, which is not in the URDF")
            continue
        if n in replaced:
            problems.append(f"joint_name names joint {quote(n)} twice")
            continue
        replaced.add(n)
        if joint_types[n] == "fixed":
            if canonical != "FIXED":
                problems.append(f"joint_name names joint {quote(n)}, which is fixed: a {canonical} replacement "
                                "must name a moving joint")
            continue
        spec.replacements.append((n, canonical))


def read_yaml_sidecar(spec: MechanismSpec, yaml_path: Path, frame_names: Iterable[str],
                      frame_body: dict | None = None) -> None:
    """Add the loops, actuation and joint replacements of an Extended-URDF sidecar.

    ``frame_names`` are the frames of the Pinocchio model of the tree: the YAML
    names frames, not links.  ``frame_body`` (optional) maps a frame name to the
    Pinocchio joint that carries it: a pair of frames on the same body closes no loop.

    The YAML is untrusted: at most ``LIMITS.yaml_bytes``, UTF-8, no aliases (no
    "billion laughs"), no tags beyond plain data, and every field's type checked.
    """
    content = _load_mapping(yaml_path)
    problems = Problems()
    unknown = _unknown_keys(content, problems)
    _read_loops(spec, content, yaml_path, frame_names, frame_body, problems)
    _read_actuation(spec, content, problems)
    if problems:  # the misspelt key is likely the cause (closed_loops: then "0 pairs but type has 1")
        problems[:0] = unknown
    problems.fail_if_any(yaml_path)
    spec.warnings.extend(f"YAML sidecar {yaml_path}: {note} is ignored" for note in unknown)
    spec.yaml_path = str(yaml_path)


def axis_letters(t: str) -> tuple[np.ndarray, np.ndarray]:
    unit = {"X": (1.0, 0, 0), "Y": (0, 1.0, 0), "Z": (0, 0, 1.0)}
    letters = t.split("_", 1)[1] if "_" in t else "XY"
    if len(letters) != 2 or any(c not in unit for c in letters):
        letters = "XY"
    return np.array(unit[letters[0]]), np.array(unit[letters[1]])

