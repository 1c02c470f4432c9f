"""Grasp files: contacts on one object, in the object's frame (YAML, SI units).

    contacts:
      - {point: [0.05, 0, 0], normal: [-1, 0, 0], model: point_friction, mu: 0.5}
      - {point: [-0.05, 0, 0], normal: [1, 0, 0], model: soft_finger, mu: 0.5, mu_torsion: 0.01}
      - {point: [0, 0.05, 0], normal: [0, -1, 0], model: frictionless}
    planar: false

The file is untrusted, like a sidecar: at most ``LIMITS.yaml_bytes``, UTF-8, no YAML
aliases, bounded nesting (screwkin.files.xmlsafe), and every field's type and value
checked before use; all problems are collected and reported on one line.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..errors import MechanismFileError, quote
from .description import LIMITS
from .urdf import Problems
from .xmlsafe import load_yaml_text, read_regular_file
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from pathlib import Path

__all__ = ["MODELS", "MAX_CONTACTS", "MAX_MU", "Contact", "GraspSpec", "read_grasp", "parse_grasp"]

#: Contact models (Murray, Li and Sastry, ch. 5) -> wrench coordinates per contact in space.
MODELS = {"frictionless": 1, "point_friction": 3, "soft_finger": 4}
#: Most contacts a grasp file may have (real grasps have a handful; 1,000 keeps the linear
#: programs and the hull small).
MAX_CONTACTS = 1000
#: Largest friction coefficient accepted: real ones are below about 2 (rubber on rubber);
#: beyond 100 the cone is a half space written as a number.
MAX_MU = 100.0

_CONTACT_KEYS = ("point", "normal", "model", "mu", "mu_torsion")
_TOP_KEYS = ("contacts", "planar")


@dataclass(frozen=True)
class Contact:
    """One contact on the object, in the object's frame.

    point: (x, y, z) [m]; normal: unit (x, y, z) pointing into the object; model: a key of
    MODELS; mu: Coulomb friction coefficient (0 for frictionless); mu_torsion: soft finger's
    torsion coefficient [m], |torsion about the normal| <= mu_torsion * normal force (0 else)."""

    point: tuple
    normal: tuple
    model: str
    mu: float = 0.0
    mu_torsion: float = 0.0


@dataclass(frozen=True)
class GraspSpec:
    """Contacts on one object; planar: wrenches (fx, fy, mz) in the plane z = 0."""

    contacts: tuple
    planar: bool = False
    path: str = "<grasp>"


def _is_number(x: str | float) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool)


def _vector(value: list, what: str, planar: bool, problems: Problems) -> tuple | None:
    """A 3-tuple of floats from a YAML list (planar: 2 numbers, or 3 with z = 0), or None."""
    sizes = "2 or 3" if planar else "3"
    if not isinstance(value, list):
        problems.append(f"{what} must be a list of {sizes} numbers, got {quote(value)}")
        return None
    if len(value) not in ((2, 3) if planar else (3,)):
        problems.append(f"{what} {quote(value)} has {len(value)} number{'' if len(value) == 1 else 's'}, "
                        f"expected {sizes}")
        return None
    if not all(_is_number(x) for x in value):
        problems.append(f"{what} {quote(value)} is not a list of numbers")
        return None
    try:
        v = [float(x) for x in value]
    except OverflowError:  # an integer of 400 digits
        problems.append(f"{what} {quote(value)} contains a number too large for a float")
        return None
    if not all(math.isfinite(x) for x in v):
        problems.append(f"{what} {quote(value)} contains NaN or infinite numbers")
        return None
    if any(abs(x) > LIMITS.length for x in v):
        problems.append(f"{what} {quote(value)}: not a plausible value (beyond {LIMITS.length:g})")
        return None
    if len(v) == 2:
        v.append(0.0)
    if planar and v[2] != 0.0:
        problems.append(f"{what} {quote(value)} leaves the plane z = 0 of a planar grasp")
        return None
    return tuple(v)


def _coefficient(c: dict, key: str, k: int, problems: Problems, bound: float, unit: str = "") -> float | None:
    value = c.get(key)
    if not _is_number(value):
        problems.append(f"contact {k}: {key} must be a number, got {quote(value)}")
        return None
    try:
        x = float(value)
    except OverflowError:
        problems.append(f"contact {k}: {key} {quote(value)} is too large for a float")
        return None
    if not math.isfinite(x):
        problems.append(f"contact {k}: {key} {quote(value)} is NaN or infinite")
        return None
    if x < 0:
        problems.append(f"contact {k}: {key} {x:g} is negative")
        return None
    if x > bound:
        problems.append(f"contact {k}: {key} {x:g}{unit} is not a plausible value (beyond {bound:g})")
        return None
    return x


def _contact(c: dict, k: int, planar: bool, problems: Problems) -> Contact | None:
    if not isinstance(c, dict):
        problems.append(f"contact {k} must be a mapping with point, normal, model, got {quote(c)}")
        return None
    n0 = len(problems)
    for key in c:
        if key not in _CONTACT_KEYS:
            problems.append(f"contact {k}: unknown key {quote(key)} (known: {', '.join(_CONTACT_KEYS)})")
    model = c.get("model")
    if model is None:
        problems.append(f"contact {k}: model is missing (one of {', '.join(MODELS)})")
    elif not isinstance(model, str) or model not in MODELS:
        problems.append(f"contact {k}: unknown model {quote(model)} (known: {', '.join(MODELS)})")
        model = None
    point = normal = None
    for key in ("point", "normal"):
        if key not in c:
            problems.append(f"contact {k}: {key} is missing")
    if "point" in c:
        point = _vector(c["point"], f"contact {k}: point", planar, problems)
    if "normal" in c:
        normal = _vector(c["normal"], f"contact {k}: normal", planar, problems)
    if normal is not None:
        size = math.sqrt(sum(x * x for x in normal))
        if size == 0.0:
            problems.append(f"contact {k}: normal is the zero vector (it must point into the object)")
            normal = None
        elif size < LIMITS.axis_min:
            problems.append(f"contact {k}: normal {quote(c['normal'])} is too short to give a direction "
                            f"(length {size:.3g} < {LIMITS.axis_min:g})")
            normal = None
        else:
            normal = tuple(x / size for x in normal)
    mu = mu_t = 0.0
    if model == "frictionless":
        for key in ("mu", "mu_torsion"):
            if key in c and c[key] != 0:
                problems.append(f"contact {k}: a frictionless contact has no {key} (got {quote(c[key])}): "
                                "write model: point_friction or soft_finger, or remove it")
    elif model in ("point_friction", "soft_finger"):
        if "mu" not in c:
            problems.append(f"contact {k}: mu is missing (a {model} contact needs its friction coefficient)")
        else:
            mu = _coefficient(c, "mu", k, problems, MAX_MU)
        if model == "soft_finger":
            if "mu_torsion" not in c:
                problems.append(f"contact {k}: mu_torsion is missing (a soft finger needs its torsion "
                                "coefficient [m]: |torsion| <= mu_torsion * normal force)")
            else:
                mu_t = _coefficient(c, "mu_torsion", k, problems, LIMITS.length, " m")
        elif "mu_torsion" in c and c["mu_torsion"] != 0:
            problems.append(f"contact {k}: a point_friction contact has no mu_torsion (got "
                            f"{quote(c['mu_torsion'])}): write model: soft_finger, or remove it")
    if model == "soft_finger" and planar:
        problems.append(f"contact {k}: a soft finger cannot be part of a planar grasp (its torsion acts about "
                        "the normal, which lies in the plane: a moment out of the plane)")
    if len(problems) > n0:
        return None
    return Contact(point, normal, model, mu, mu_t)


def parse_grasp(content, path: str="<grasp>") -> GraspSpec:
    """A GraspSpec from the plain data of a grasp file (what the YAML loads to), every
    problem collected and raised at once as a MechanismFileError naming ``path``."""
    if content is None:
        raise MechanismFileError(path, "the file is empty (expected a mapping with contacts)")
    if not isinstance(content, dict):
        raise MechanismFileError(path, f"expected a mapping with contacts and planar, got {quote(content)}")
    problems = Problems()
    for key in content:
        if key not in _TOP_KEYS:
            problems.append(f"unknown key {quote(key)} (known: {', '.join(_TOP_KEYS)})")
    planar = content.get("planar", False)
    if not isinstance(planar, bool):
        problems.append(f"planar must be true or false, got {quote(planar)}")
        planar = False
    contacts = content.get("contacts")
    if contacts is None:
        problems.append("no contacts (write contacts: a list of {point, normal, model, ...})")
        contacts = []
    elif not isinstance(contacts, list):
        problems.append(f"contacts must be a list of contacts, got {quote(contacts)}")
        contacts = []
    elif not contacts:
        problems.append("no contacts: the contacts list is empty")
    elif len(contacts) > MAX_CONTACTS:
        raise MechanismFileError(path, f"{len(contacts)} contacts; screwkin reads grasps of at most "
                                       f"{MAX_CONTACTS:,} contacts")
    out = [_contact(c, k, planar, problems) for k, c in enumerate(contacts, 1)]
    problems.fail_if_any(path)
    return GraspSpec(tuple(out), planar, str(path))


def read_grasp(path: str | Path) -> GraspSpec:
    """Read a grasp file (see the module's notes); one-line MechanismFileError naming it
    for every problem."""
    raw = read_regular_file(path, LIMITS.yaml_bytes, "grasp file")
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError:
        raise MechanismFileError(path, "not a text file (not UTF-8)") from None
    if not text.strip():
        raise MechanismFileError(path, "the file is empty (expected a mapping with contacts)")
    return parse_grasp(load_yaml_text(text, path), path)
