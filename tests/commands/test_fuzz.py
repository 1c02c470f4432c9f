"""Fuzzing the input handling: hostile variants of the robots' own files.

A seeded mutator turns the URDF files of robots/ (and the YAML sidecars of the
example-parallel-robots corpus) into broken, strange or hostile files: elements
deleted, duplicated, moved or swapped, attribute values replaced by NaN, 1e308,
5,000 characters, control characters or names of other elements, joints named
like links, types changed, hundreds of loop joints, truncation, comments,
entities, bytes that are not UTF-8.  Each mutant goes through ``screwkin info``,
``mobility --json`` and ``solve --set <first actuated>=0.1 --json`` in process,
and the contract for bad input is checked: exit code 0, 1 or 2 (never 3), no
traceback, at most one short error line on stderr besides ``warning:`` lines,
and when the command succeeds with --json, JSON without NaN.

The mutants are a pure function of their index (SEED, MUTANTS): a failure names
the mutant, and ``describe(i)`` says what was done to which file.
"""

from __future__ import annotations

import contextlib
import copy
import functools
import io
import json
import os
import random
import subprocess
import sys
import xml.etree.ElementTree as ET

import pytest
import yaml
from conftest import CORPUS, DATA, ROBOTS, fourbar, no_hang
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from screwkin.cli import main
from screwkin.errors import UsageError
from screwkin.units import UNITS

SEED = 20240611
#: Number of URDF mutants (each runs info, mobility and solve) and of YAML-sidecar mutants.
MUTANTS = 200
YAML_MUTANTS = 48
SDF_MUTANTS = 40

#: Mutants that still fail in code this test does not own (closure, position, mobility...):
#: "urdf-<index>:<command>", "sdf-<index>:<command>" or "yaml-<index>:<command>" -> what goes wrong.  Each is excluded
#: from the assertions (and reported); the list should be empty.
KNOWN_FAILURES: dict[str, str] = {}

#: kangaroo_like is left out: its welds cannot close, so every command on it runs a whole failing
#: assembly (63 coordinates, 66 rows): it alone took 60 % of this file's time; wl16_like and
#: digit_like (42 and 27 coordinates) stand for the large files.
SLOW = {"kangaroo_like"}
BASES = sorted(ROBOTS.glob("*.urdf")) + sorted(p for p in CORPUS.glob("*/robot.urdf") if p.parent.name not in SLOW)
YAML_BASES = sorted(p for p in CORPUS.glob("*/robot.yaml") if p.parent.name not in SLOW)

HOSTILE = ["nan", "inf", "-inf", "1e308", "-1e308", "1e-320", "-0", "", " ", "x" * 5000, "0 0 0", "1 2",
           "1 2 3 4", "1e999", "0x10", "1_000", "\u0661", "revolute\nrevolute", "a\x1b[31mb", "\u202e", "-1",
           "1.79769e+308", "0.1 0.2 nan", "1e6 1e6 1e6", "package://" + "p" * 300 + "/m.stl", "1,2,3"]
TYPES = ["revolute", "continuous", "prismatic", "fixed", "floating", "planar", "spherical", "universal",
         "cylindrical", "ball", "hinge", "", "REVOLUTE", "revolute\nrevolute"]


# ------------------------------------------------------------------ the mutator
def _parents(root):
    return {child: parent for parent in root.iter() for child in parent}


def _names(root, tag):
    return [e.get("name") for e in root.iter(tag) if e.get("name")]


def _op_delete(root, rng):
    parents = _parents(root)
    elems = list(parents)
    if not elems:
        return None
    e = rng.choice(elems)
    parents[e].remove(e)
    return f"delete <{e.tag} {e.get('name', '')}>"


def _op_duplicate(root, rng):
    parents = _parents(root)
    elems = list(parents)
    if not elems:
        return None
    e = rng.choice(elems)
    parent = parents[e]
    parent.insert(list(parent).index(e) + 1, copy.deepcopy(e))
    return f"duplicate <{e.tag} {e.get('name', '')}>"


def _op_move(root, rng):
    parents = _parents(root)
    elems = list(parents)
    if len(elems) < 2:
        return None
    e, target = rng.sample(elems, 2)
    if e in target.iter() or target in e.iter():
        return None
    parents[e].remove(e)
    target.append(e)
    return f"move <{e.tag} {e.get('name', '')}> into <{target.tag} {target.get('name', '')}>"


def _op_swap_names(root, rng):
    named = [e for e in root.iter() if e.get("name")]
    if len(named) < 2:
        return None
    a, b = rng.sample(named, 2)
    na, nb = a.get("name"), b.get("name")
    a.set("name", nb)
    b.set("name", na)
    return f"swap names {na!r} and {nb!r}"


def _op_hostile_value(root, rng):
    elems = [e for e in root.iter() if e.attrib]
    if not elems:
        return None
    e = rng.choice(elems)
    key = rng.choice(sorted(e.attrib))
    value = rng.choice(HOSTILE)
    e.set(key, value)
    return f"<{e.tag} {key}> = {value[:20]!r}"


def _op_other_name(root, rng):
    elems = [e for e in root.iter() if e.get("name") or e.get("link")]
    names = _names(root, "link") + _names(root, "joint") + _names(root, "loop_joint")
    if not elems or not names:
        return None
    e = rng.choice(elems)
    key = "link" if e.get("link") else "name"
    value = rng.choice(names)
    e.set(key, value)
    return f"<{e.tag} {key}> = {value!r}"


def _op_joint_like_link(root, rng):
    joints, links = root.findall("joint"), _names(root, "link")
    if not joints or not links:
        return None
    j, name = rng.choice(joints), rng.choice(links)
    old = j.get("name")
    j.set("name", name)
    for t in root.iter("transmission"):  # keep the file otherwise consistent
        for tj in t.iter("joint"):
            if tj.get("name") == old:
                tj.set("name", name)
    return f"joint {old!r} renamed like link {name!r}"


def _op_type(root, rng):
    elems = list(root.iter("joint")) + list(root.iter("loop_joint"))
    elems = [e for e in elems if e.get("type") is not None]
    if not elems:
        return None
    e = rng.choice(elems)
    t = rng.choice(TYPES)
    e.set("type", t)
    return f"<{e.tag} {e.get('name')}> type = {t!r}"


def _op_many_loops(root, rng):
    loops = root.findall("loop_joint")
    if not loops:
        return None
    e = rng.choice(loops)
    n = rng.choice([3, 12, 250])
    for k in range(n):
        c = copy.deepcopy(e)
        c.set("name", f"{e.get('name')}_dup{k}")
        root.append(c)
    return f"{n} copies of loop joint {e.get('name')!r}"


def _op_third_link(root, rng):
    loops = root.findall("loop_joint")
    links = _names(root, "link")
    if not loops or not links:
        return None
    e = rng.choice(loops)
    ET.SubElement(e, rng.choice(["link1", "link2"]), link=rng.choice(links))
    return f"third link child in {e.get('name')!r}"


def _op_numbers(root, rng):
    elems = [e for e in root.iter() if e.get("xyz") is not None or e.get("rpy") is not None]
    if not elems:
        return None
    e = rng.choice(elems)
    key = "xyz" if e.get("xyz") is not None else "rpy"
    value = rng.choice(["1 2", "1 2 3 4", "1e308 0 0", "0 0 1e-300", "nan 0 0", "1e5 0 0", "0 0 0", "-0 -0 -0",
                        "3e4 0 0", "1 1 1e300"])
    e.set(key, value)
    return f"<{e.tag} {key}> = {value!r}"


def _op_limits(root, rng):
    limits = list(root.iter("limit"))
    if not limits:
        return None
    e = rng.choice(limits)
    lo, hi = rng.choice([("1e308", "-1e308"), ("0.5", "0.1"), ("-1e16", "1e16"), ("nan", "1"), ("0", "0"),
                         ("-1.79769e+308", "1.79769e+308"), ("", "1")])
    e.set("lower", lo)
    e.set("upper", hi)
    return f"<limit lower={lo!r} upper={hi!r}>"


def _op_transmission(root, rng):
    names = _names(root, "joint") + ["ghost"]
    name = rng.choice(names)
    t = ET.SubElement(root, "transmission", name="t_fuzz")
    ET.SubElement(t, "joint", name=name)
    return f"transmission naming {name!r}"


def _op_valid_type(root, rng):
    """A type change that keeps the file valid: the kinematics change, the file does not break."""
    joints, loops = root.findall("joint"), root.findall("loop_joint")
    if not joints and not loops:
        return None
    e = rng.choice(joints + loops)
    if e.tag == "joint":
        t = rng.choice(["revolute", "continuous", "prismatic", "fixed", "floating", "planar"])
    else:
        t = rng.choice(["fixed", "revolute", "prismatic", "cylindrical", "universal", "planar", "spherical"])
        if t == "universal" and e.find("axis2") is None:
            ET.SubElement(e, "axis2", xyz="0 1 0")
    e.set("type", t)
    return f"<{e.tag} {e.get('name')}> type = {t!r} (valid)"


def _op_geometry(root, rng):
    """Valid but strange geometry: a random axis, a moved or collapsed origin."""
    elems = [e for e in root.iter() if e.tag in ("axis", "axis2", "origin", "link1", "link2")]
    if not elems:
        return None
    e = rng.choice(elems)
    if e.tag.startswith("axis"):
        v = rng.choice(["1 1 1", "0 0 -1", "1e-5 0 0", "0.0446 -0.0825 1.8977", "1 0 1e-12",
                        " ".join(f"{rng.uniform(-1, 1):.3g}" for _ in range(3))])
        e.set("xyz", v)
        return f"<{e.tag} xyz> = {v!r}"
    factor = rng.choice([0.0, 1e-9, -1.0, 1000.0, 1.5])
    xyz = [float(x) * factor for x in (e.get("xyz") or "0 0 0").split()] if len(
        (e.get("xyz") or "0 0 0").split()) == 3 else [0.0, 0.0, 0.0]
    e.set("xyz", " ".join(repr(x) for x in xyz))
    if rng.random() < 0.3:
        e.set("rpy", " ".join(f"{rng.uniform(-7, 7):.4g}" for _ in range(3)))
    return f"<{e.tag} {e.get('name') or e.get('link') or ''}> xyz scaled by {factor}"


def _op_hostile_text(root, rng):
    """SDF keeps its numbers and names in element text: <pose>, <xyz>, <parent>, <mass>."""
    elems = [e for e in root.iter() if (e.text or "").strip() and len(e) == 0]
    if not elems:
        return None
    e = rng.choice(elems)
    names = _names(root, "link") + _names(root, "joint")
    value = rng.choice(HOSTILE + names + ["world", "0 0 0 0 0 1e308", "1 2 3 4 5", "0 0 0 nan 0 0"])
    e.text = value
    return f"<{e.tag}> text = {value[:20]!r}"


SDF_OPS = [_op_hostile_text, _op_hostile_text, _op_hostile_text, _op_delete, _op_duplicate, _op_move, _op_swap_names,
           _op_hostile_value, _op_type, _op_type]
TREE_OPS = [_op_hostile_text, _op_valid_type, _op_valid_type, _op_geometry, _op_geometry, _op_delete, _op_duplicate, _op_move, _op_swap_names, _op_hostile_value, _op_hostile_value,
            _op_other_name, _op_joint_like_link, _op_type, _op_many_loops, _op_third_link, _op_numbers,
            _op_numbers, _op_limits, _op_transmission]


def _text_op(data: bytes, rng):
    kind = rng.choice(["truncate", "comment", "entity", "doctype", "sdf_comment", "not_utf8", "bom", "control",
                       "nested"])
    if kind == "truncate":
        n = rng.randrange(len(data))
        return data[:n], f"truncated at {n}"
    if kind == "comment":
        return b"<!--" + data.replace(b"--", b"- -") + b"-->", "wrapped in a comment"
    if kind == "entity":
        return (b'<?xml version="1.0"?><!DOCTYPE robot [<!ENTITY e "ent">]>' + data.replace(b'name="', b'name="&e;', 1),
                "entity declared and used")
    if kind == "doctype":
        return b"<!DOCTYPE robot>" + data, "DOCTYPE without entities"
    if kind == "sdf_comment":
        return b"<!-- an <sdf version='1.7'> model once -->" + data, "<sdf in a comment"
    if kind == "not_utf8":
        n = rng.randrange(len(data))
        return data[:n] + b"\xff\xfe" + data[n:], f"bytes 0xff 0xfe at {n}"
    if kind == "bom":
        return b"\xef\xbb\xbf" + data, "UTF-8 BOM"
    if kind == "control":
        n = rng.randrange(len(data))
        return data[:n] + b"\x01" + data[n:], f"control character at {n}"
    depth = rng.choice([50, 150])
    return data.replace(b"</robot>", b"<x>" * depth + b"</x>" * depth + b"</robot>"), f"{depth} nested elements"


#: SDF bases in tests/data: the four-bar and an RSSR with ball joints (one in the tree, one cut).
SDF_BASES = {name: (DATA / name).read_text() for name in ("fourbar.sdf", "rssr.sdf")}

def _mutate(text: str, rng, ops):
    root = ET.fromstring(text)
    done = []
    for _ in range(rng.choice([1, 1, 1, 2, 3])):
        d = rng.choice(ops)(root, rng)
        if d:
            done.append(d)
    data = ET.tostring(root, encoding="unicode").encode()
    if rng.random() < 0.2:
        data, d = _text_op(data, rng)
        done.append(d)
    return data, "; ".join(done) or "unchanged"


@functools.cache
def sdf_mutant(i: int):
    """(base name, mutated bytes, description) of SDF mutant i."""
    rng = random.Random(SEED * 3_000_017 + i)
    name = sorted(SDF_BASES)[i % len(SDF_BASES)]
    data, what = _mutate(SDF_BASES[name], rng, SDF_OPS)
    return name, data, what


@functools.cache
def urdf_mutant(i: int):
    """(base file, mutated bytes, description) of URDF mutant i."""
    rng = random.Random(SEED * 1_000_003 + i)
    base = BASES[i % len(BASES)]
    data, what = _mutate(base.read_text(), rng, TREE_OPS)
    return base, data, what


def describe(i: int) -> str:
    base, _, what = urdf_mutant(i)
    return f"urdf-{i:03d} {base.relative_to(ROBOTS.parent)}: {what}"


def _hostile_structure(rng):
    deep = "x"
    for _ in range(rng.choice([5, 150])):
        deep = [deep]
    return rng.choice([[["a"], ["b"]], {"a": 1}, 5, True, None, "x" * 5000, [[1, 2, 3]], [["a", "b", "c"]],
                       ["3d"] * 50, ["7d"], deep, [None], [{"k": "v"}], "closedloop1_A", [["\x1b[2J", "a\nb"]], 1e308,
                       [[True, False]], [], ["mot1", "mot1"]])


@functools.cache
def yaml_mutant(i: int):
    """(folder of the robot, mutated YAML bytes, description) of sidecar mutant i."""
    rng = random.Random(SEED * 7_000_003 + i)
    src = YAML_BASES[i % len(YAML_BASES)]
    content = yaml.safe_load(src.read_text())
    root = ET.fromstring((src.parent / "robot.urdf").read_text())
    joints = [(j.get("name"), j.get("type")) for j in root.iter("joint")]
    frames = [j for j, _ in joints] + _names(root, "link")
    done = []
    for _ in range(rng.choice([1, 1, 2])):
        kind = rng.choice(["hostile", "hostile", "self_pair", "same_body", "swap", "drop", "unknown_key",
                           "replace", "replace_fixed", "name_mot_fixed"])
        key = rng.choice(["closed_loop", "type", "name_mot", "joint_name", "joint_type"])
        if kind == "hostile":
            content[key] = _hostile_structure(rng)
            done.append(f"{key} = hostile {str(content[key])[:30]!r}")
        elif kind == "self_pair" and content.get("closed_loop"):
            f = rng.choice(frames)
            content["closed_loop"] = [[f, f]] + list(content["closed_loop"])[1:]
            content["type"] = ["6d"] * len(content["closed_loop"])
            done.append(f"self pair {f!r}")
        elif kind == "same_body":
            fixed = [(j.find("parent").get("link"), j.find("child").get("link")) for j in root.iter("joint")
                     if j.get("type") == "fixed" and j.find("parent") is not None and j.find("child") is not None]
            if fixed:
                a, b = rng.choice(fixed)
                content["closed_loop"], content["type"] = [[a, b]], ["6d"]
                done.append(f"pair on one body {a!r} {b!r}")
        elif kind == "swap" and content.get("closed_loop"):
            pairs = [list(p) for p in content["closed_loop"]]
            p = rng.choice(pairs)
            p[rng.randrange(2)] = rng.choice(frames)
            content["closed_loop"] = pairs
            done.append("a frame of a pair replaced")
        elif kind == "drop":
            content.pop(key, None)
            done.append(f"drop {key}")
        elif kind == "unknown_key":
            content[rng.choice(["closed_loops", 5, "x" * 300])] = [1]
            done.append("unknown key")
        elif kind in ("replace", "replace_fixed"):
            pool = [j for j, t in joints if (t == "fixed") == (kind == "replace_fixed")]
            if pool:
                j = rng.choice(pool)
                t = rng.choice(["SPHERICAL", "CARDAN", "UJOINT_XZ", "UJOINT_XX", "FIXED", "hinge", "ujoint_yz"])
                content["joint_name"], content["joint_type"] = [j], [t]
                done.append(f"replace {j!r} by {t}")
        elif kind == "name_mot_fixed":
            pool = [j for j, t in joints if t == "fixed"]
            if pool:
                content["name_mot"] = [rng.choice(pool)]
                done.append("name_mot names a fixed joint")
    data = yaml.safe_dump(content, default_flow_style=True, allow_unicode=True).encode()
    if rng.random() < 0.3:
        kind = rng.choice(["alias_bomb", "not_utf8", "truncate", "tag", "tab", "bom", "deep"])
        if kind == "alias_bomb":
            bomb = "a: &a [x,x,x,x,x,x,x,x,x]\n" + "".join(
                f"{n}: &{n} [{','.join([f'*{p}'] * 9)}]\n" for p, n in zip("abcdefgh", "bcdefghi"))
            data = bomb.encode() + b"name_mot: *i\n"
        elif kind == "not_utf8":
            data = data[:5] + b"\xff" + data[5:]
        elif kind == "truncate":
            data = data[: rng.randrange(len(data))]
        elif kind == "tag":
            data = b"name_mot: !!python/object/apply:os.system ['true']\n"
        elif kind == "tab":
            data = b"\tname_mot: [a]\n"
        elif kind == "bom":
            data = b"\xef\xbb\xbf" + data
        else:
            data = b"name_mot: " + b"[" * 5000 + b"]" * 5000 + b"\n"
        done.append(kind)
    return src.parent, data, "; ".join(done) or "unchanged"


# ------------------------------------------------------------------ the contract
@functools.cache
def first_input(base) -> str:
    """The first actuated joint of the pristine file (else its first moving joint)."""
    import screwkin

    mech = screwkin.load(base, warn=lambda m: None)
    return (mech.actuated or [c.joint for c in mech.coordinates])[0]


def _no_nan(token):
    raise ValueError(f"JSON constant {token} in the output")


def check_contract(argv, capfd, paths, known=None, full=False):
    """Run ``screwkin argv`` in process and check the contract for bad input: its exit code (with ``full``,
    (code, stdout, stderr))."""
    code = main(argv)
    out, err = capfd.readouterr()
    if known:
        return code
    where = f"{argv[0]} {' '.join(argv[1:])[:200]}"
    assert code in (0, 1, 2), f"exit {code} for {where}:\n{err[-2000:]}"
    assert "Traceback" not in err and "internal error" not in err, f"{where}:\n{err[-2000:]}"
    lines = err.splitlines()
    errors = [line for line in lines if not line.startswith(("warning: ", "note: "))]  # notes say what was chosen
    assert len(errors) <= 1, f"{where}: several error lines:\n{err[-2000:]}"
    for line in errors:
        short = line
        for p in paths:
            short = short.replace(str(p), "F")
        assert short.startswith("screwkin: error: "), f"{where}: {line[:300]}"
        assert len(short) <= 340, f"{where}: an error line of {len(short)} characters: {short[:400]}"
    for line in lines:
        assert len(line) <= 800, f"{where}: a warning line of {len(line)} characters: {line[:300]}"
    if code == 0 and "--json" in argv:
        json.loads(out, parse_constant=_no_nan)
    if code != 0:
        assert errors, f"{where}: exit {code} without an error line"
    return (code, out, err) if full else code


def _write_urdf_mutant(i, tmp_path):
    base, data, _ = urdf_mutant(i)
    path = tmp_path / f"m{base.suffix}"
    path.write_bytes(data)
    sidecar = base.with_suffix(".yaml")
    if sidecar.is_file():
        (tmp_path / "m.yaml").write_bytes(sidecar.read_bytes())
    return base, path


@pytest.mark.parametrize("i", range(MUTANTS), ids=lambda i: f"urdf-{i:03d}")
def test_urdf_mutant(i, tmp_path, capfd):
    base, path = _write_urdf_mutant(i, tmp_path)
    first = first_input(base)
    runs = {"info": ["info", str(path)], "mobility": ["mobility", str(path), "--json"],
            "solve": ["solve", str(path), "--set", f"{first}=0.1", "--json", "--starts", "2"]}
    for name, argv in runs.items():
        known = KNOWN_FAILURES.get(f"urdf-{i:03d}:{name}")
        check_contract(argv, capfd, [path, tmp_path / "m.yaml"], known)


@functools.cache
def _sdf_first_input(name) -> str:
    import tempfile

    path = os.path.join(tempfile.mkdtemp(), name)
    with open(path, "w") as f:
        f.write(SDF_BASES[name])
    return first_input(path)


@pytest.mark.parametrize("i", range(SDF_MUTANTS), ids=lambda i: f"sdf-{i:03d}")
def test_sdf_mutant(i, tmp_path, capfd):
    name, data, _ = sdf_mutant(i)
    path = tmp_path / "m.sdf"
    path.write_bytes(data)
    first = _sdf_first_input(name)
    runs = {"info": ["info", str(path)], "mobility": ["mobility", str(path), "--json"],
            "solve": ["solve", str(path), "--set", f"{first}=0.1", "--json", "--starts", "2"]}
    for cmd, argv in runs.items():
        check_contract(argv, capfd, [path], KNOWN_FAILURES.get(f"sdf-{i:03d}:{cmd}"))


@pytest.mark.parametrize("i", range(YAML_MUTANTS), ids=lambda i: f"yaml-{i:03d}")
def test_yaml_mutant(i, tmp_path, capfd):
    folder, data, _ = yaml_mutant(i)
    path = tmp_path / "robot.urdf"
    path.write_bytes((folder / "robot.urdf").read_bytes())
    (tmp_path / "robot.yaml").write_bytes(data)
    first = first_input(folder / "robot.urdf")
    runs = {"info": ["info", str(path)], "mobility": ["mobility", str(path), "--json"],
            "solve": ["solve", str(path), "--set", f"{first}=0.1", "--json", "--starts", "2"]}
    for name, argv in runs.items():
        known = KNOWN_FAILURES.get(f"yaml-{i:03d}:{name}")
        check_contract(argv, capfd, [path, tmp_path / "robot.yaml"], known)


# ------------------------------------------------------------------ hypothesis: typed values and sidecars

@settings(max_examples=200, deadline=None, database=None)
@given(st.text(max_size=60))
def test_parse_value_on_any_text(text):
    import math

    from screwkin.errors import UsageError
    from screwkin.units import parse_value

    try:
        value = parse_value(text)
    except UsageError as exc:
        assert "\n" not in str(exc) and len(str(exc)) < 250, str(exc)
    else:
        assert math.isfinite(value)


@settings(max_examples=200, deadline=None, database=None)
@given(st.floats(min_value=-1e6, max_value=1e6), st.sampled_from(sorted(UNITS)),
       st.sampled_from(["", " "]), st.booleans())
def test_parse_value_reads_numbers_with_units(x, unit, space, upper):
    from screwkin.units import UNITS, parse_value

    typed = unit.upper() if upper and unit.isascii() else unit
    if sum(u.upper() == typed.upper() for u in UNITS if u.isascii()) > 1 and typed not in UNITS:
        with pytest.raises(UsageError, match="ambiguous"):  # NM: nanometre or newton metre
            parse_value(f"{x!r}{space}{typed}")
        return
    assert parse_value(f"{x!r}{space}{typed}") == x * UNITS[unit]


_5BAR = CORPUS / "5bar_linkage"
_FRAMES = ["closedloop1_A", "closedloop1_B", "mot1", "mot2", "end_rod", "effector", "effector_frame"]
_LEAVES = st.one_of(st.none(), st.booleans(), st.integers(), st.floats(), st.text(max_size=12),
                    st.sampled_from(_FRAMES + ["3d", "6d", "SPHERICAL", "CARDAN", "FIXED", "UJOINT_XZ"]))
_VALUES = st.recursive(_LEAVES, lambda c: st.lists(c, max_size=4) | st.dictionaries(st.text(max_size=4), c, max_size=3),
                       max_leaves=10)
_SIDECARS = st.dictionaries(st.sampled_from(["closed_loop", "type", "name_mot", "joint_name", "joint_type", "x"]),
                            _VALUES, max_size=5)


@settings(max_examples=40, deadline=None, database=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(_SIDECARS)
def test_sidecar_from_any_structure(tmp_path, content):
    path = tmp_path / "robot.urdf"
    if not path.exists():
        path.write_bytes((_5BAR / "robot.urdf").read_bytes())
    (tmp_path / "robot.yaml").write_text(yaml.safe_dump(content, allow_unicode=True))
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(["mobility", str(path), "--json"])
    lines = [line for line in err.getvalue().splitlines() if not line.startswith("warning: ")]
    assert code in (0, 1, 2) and "Traceback" not in err.getvalue(), err.getvalue()
    assert len(lines) <= 1 and all(len(line.replace(str(tmp_path), "D")) <= 340 for line in lines), lines
    if code == 0:
        json.loads(out.getvalue(), parse_constant=_no_nan)


# ------------------------------------------------------------------ hostile command lines (issue 22)
#: Values typed into options: huge and negative counts, empty values, subnormals, units of the wrong kind,
#: spreadsheet formulas, names with dots, commas and newlines, paths that cannot be written.
OPTION_VALUES = ["", " ", "0", "-1", "1", "3", "100000000", "1e9", "5e-324", "nan", "inf", "1e308", "30mm",
                 "90deg", "-90deg", "1_000", "0x10", "=1+1", "a,b", "a\nb", "a.b", "1turn", "-0"]
OUTPUT_VALUES = ["missing/out.file", ".", "out.csv", "=HYPERLINK(x).csv"]
_FOURBAR = str(ROBOTS / "fourbar_crank_rocker.urdf")
_FIVE = str(ROBOTS / "five_bar.urdf")
_ARM = str(ROBOTS / "arm_6r.urdf")
#: Command lines with one slot ({v}: a value, {o}: an output path) each filled from the lists above.
COMMAND_LINES = [
    ["sweep", _FOURBAR, "--input", "crank_joint", "--from", "0", "--to", "1", "--steps", "{v}"],
    ["sweep", _FOURBAR, "--input", "crank_joint", "--from", "{v}", "--to", "1", "--steps", "3"],
    ["sweep", _FOURBAR, "--input", "crank_joint", "--from", "0", "--to", "1", "--steps", "3", "--rate", "{v}"],
    ["sweep", _FOURBAR, "--input", "crank_joint", "--from", "0", "--to", "1", "--steps", "3", "--csv", "{o}"],
    ["sweep", _FOURBAR, "--input", "crank_joint", "--from", "0", "--to", "1", "--steps", "3", "--output", "{v}"],
    ["solve", _FOURBAR, "--set", "crank_joint={v}", "--json"],
    ["solve", _FOURBAR, "--set", "crank_joint=1", "--starts", "{v}", "--json"],
    ["solve", _FOURBAR, "--set", "crank_joint=1", "--length", "{v}", "--json"],
    ["solve", _FOURBAR, "--set", "crank_joint=1", "--near", "rocker_joint={v}", "--json"],
    ["solve", _FOURBAR, "--set", "crank_joint=1", "--start", "rocker={v}", "--iterations", "2"],
    ["map", _FIVE, "--x", "motor1=0:1:{v}", "--y", "motor2=0:1:3", "--json"],
    ["map", _FIVE, "--x", "motor1=0:1:3", "--y", "motor2=0:1:3", "--csv", "{o}"],
    ["scan", _ARM, "--output", "flange", "--samples", "{v}", "--json"],
    ["scan", _ARM, "--output", "flange", "--samples", "10", "--seed", "{v}", "--json"],
    ["draw", _FOURBAR, "--svg", "{o}"],
    ["draw", _FOURBAR, "--svg", "d.svg", "--singular", "--steps", "{v}"],
    ["singularities", _FOURBAR, "--set", "crank_joint={v}", "--output", "rocker", "--json"],
    ["ik", _ARM, "--output", "flange", "--pose", "0.3 0 0.3 0 0 {v}", "--starts", "2", "--json"],
    ["synthesize", "chains", "--links", "{v}", "--dof", "1", "--json"],
    ["mobility", _FIVE, "--output", "{v}", "--json"],
    # this session's inputs and outputs: a floating link's angle, rates in typed units, branches, drawings
    ["solve", _FIVE, "--set", "motor1=0.3", "--set-angle", "distal1={v}", "--json"],
    ["solve", _FOURBAR, "--set-angle", "coupler={v}", "--rate", "coupler=1", "--json"],
    ["solve", _FOURBAR, "--set", "crank_joint=1", "--rate", "crank_joint={v}"],
    ["sweep", _FOURBAR, "--input", "crank_joint", "--from", "0", "--to", "360deg", "--steps", "7", "--rate", "{v}"],
    ["ik", _FIVE, "--output", "distal1", "--position", "{v},0.1,0", "--starts", "2", "--json"],
    ["synthesize", "path", "--points", "0,0; 0.05,{v}; 0.1,0.05; 0.12,0.1; 0.08,0.12", "--starts", "2",
     "--draw", "{o}"],
    ["synthesize", "chains", "--links", "6", "--dof", "1", "-o", "{o}"],
]
CLI_MUTANTS = 110


@functools.cache
def command_line(i: int):
    rng = random.Random(SEED * 7 + i)
    template = COMMAND_LINES[i % len(COMMAND_LINES)]
    value, out = rng.choice(OPTION_VALUES), rng.choice(OUTPUT_VALUES)
    return [a.replace("{v}", value).replace("{o}", out) for a in template]


@pytest.mark.parametrize("i", range(CLI_MUTANTS), ids=lambda i: f"cli-{i:03d}")
def test_hostile_command_line(i, tmp_path, capfd, monkeypatch):
    """Every command line above answers within its bound: exit 0, 1 or 2, one error line, no traceback."""
    monkeypatch.chdir(tmp_path)
    argv = command_line(i)
    with no_hang(60):
        check_contract(argv, capfd, [_FOURBAR, _FIVE, _ARM])


#: Names people (or hostile files) give links and joints: dots, commas, newlines are names, not syntax.
HOSTILE_NAMES = ["mesh.2", "a.x", "a,b", "a\nb", "=SUM(A1:A9)", "+cmd", "@x", "<script>alert(1)</script>", "j;rm -rf",
                 "crank\u00e9", "a b"]


@pytest.mark.parametrize("name", HOSTILE_NAMES)
def test_hostile_names_through_the_commands(name, tmp_path, capfd, monkeypatch):
    """A four-bar whose crank joint and coupler link carry the name: info, mobility, solve and a sweep to CSV
    keep the contract, and the CSV has rows of one length with the name intact in its header."""
    import csv
    from xml.sax.saxutils import quoteattr

    monkeypatch.chdir(tmp_path)
    text = fourbar().replace('name="crank_joint"', f"name={quoteattr(name)}")
    path = tmp_path / "named.urdf"
    path.write_text(text)
    for argv in (["info", path, "--json"], ["mobility", path, "--json"],
                 *([["solve", path, "--set", f"{name}=1", "--json"]] if "," not in name else []),  # NAME=V,...
                 ["sweep", path, "--input", name, "--from", "0", "--to", "1", "--steps", "3", "--csv", "s.csv"]):
        with no_hang(60):
            code = check_contract([str(a) for a in argv], capfd, [path])
        assert code == 0, (name, argv)
    rows = list(csv.reader(open(tmp_path / "s.csv", newline="")))
    assert len({len(r) for r in rows}) == 1 and len(rows) == 1 + 4
    assert any(name in cell for cell in rows[0])
    assert not any(cell.startswith(("=", "+", "@")) for row in rows for cell in row)  # no spreadsheet formula
    if name.startswith(("=", "+", "@")):
        assert "'" + name in rows[0]  # the joint's own column, its name kept behind an apostrophe


# ------------------------------------------------------------------ whole processes
def _screwkin(*args, timeout=120, **kw):
    return subprocess.run([sys.executable, "-m", "screwkin", *map(str, args)], capture_output=True, text=True,
                          timeout=timeout, **kw)


def test_process_closed_stdout_is_quiet():
    """``screwkin info F | head -1``: exit 141 and nothing on stderr."""
    p = subprocess.Popen([sys.executable, "-m", "screwkin", "info", ROBOTS / "fourbar_crank_rocker.urdf"],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    p.stdout.close()
    err = p.stderr.read()
    assert p.wait(timeout=120) == 141 and err == b"", err


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no named pipes here")
def test_process_fifo_input_does_not_block(tmp_path):
    fifo = tmp_path / "pipe.urdf"
    os.mkfifo(fifo)
    p = _screwkin("mobility", fifo, timeout=60)  # TimeoutExpired would be the failure
    assert p.returncode == 1 and "is not a regular file" in p.stderr and len(p.stderr.splitlines()) == 1


def test_process_native_parser_complaints_stay_one_line(tmp_path):
    """urdfdom (C++) writes to the process's file descriptor 2: only screwkin's line comes out."""
    path = tmp_path / "m.urdf"
    path.write_text('<robot name="s"><link name="a"/><link name="b"/><joint name="j" type="prismatic">'
                    '<parent link="a"/><child link="b"/><axis xyz="1 0 0"/></joint></robot>')
    p = _screwkin("info", path)
    assert p.returncode == 1 and len(p.stderr.splitlines()) == 1 and "PRISMATIC without limits" in p.stderr


@pytest.mark.parametrize("i", [1, 2], ids=lambda i: f"urdf-{i:03d}")
def test_process_mutants(i, tmp_path):
    """A few mutants as whole processes: what native code or signals do is seen too."""
    base, path = _write_urdf_mutant(i, tmp_path)
    p = _screwkin("solve", path, "--set", f"{first_input(base)}=0.1", "--json", "--starts", "2")
    errors = [line for line in p.stderr.splitlines() if not line.startswith("warning: ")]
    assert p.returncode in (0, 1, 2) and "Traceback" not in p.stderr and len(errors) <= 1, p.stderr
    if p.returncode == 0:
        json.loads(p.stdout, parse_constant=_no_nan)


# ------------------------------------------------------------------ hostile files of issue 22
MESH_ROUTES = ["../outside/secret.obj", "../../outside/secret.obj", "package://robot/../outside/secret.obj",
               "package://outside/secret.obj", "file:///etc/passwd", "/etc/passwd", "link.obj"]


@pytest.mark.parametrize("route", MESH_ROUTES)
def test_mesh_paths_that_leave_the_folder(route, tmp_path, capfd, monkeypatch):
    """A mesh outside the robot's folder (by .., package://, file://, an absolute path or a symlink) is
    never read: the view's page holds none of its bytes, and the contract holds."""
    import base64

    outside = tmp_path / "outside"
    outside.mkdir()
    token = "CANARY-" + "7f3a9c" * 4
    (outside / "secret.obj").write_text(f"# {token}\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    robot = tmp_path / "robot"
    robot.mkdir()
    (robot / "link.obj").symlink_to(outside / "secret.obj")
    mesh = f'<visual><geometry><mesh filename="{route}"/></geometry></visual>'
    text = fourbar().replace('<link name="crank">', f'<link name="crank">{mesh}', 1)
    if mesh not in text:
        text = fourbar().replace("</robot>", f'<link name="extra">{mesh}</link><joint name="fix" type="fixed">'
                                             '<parent link="ground"/><child link="extra"/></joint></robot>')
    path = robot / "robot.urdf"
    path.write_text(text)
    monkeypatch.chdir(tmp_path)
    with no_hang(60):
        code = check_contract(["view", str(path), "--html", str(tmp_path / "v.html")], capfd, [path])
    if code == 0:
        page = (tmp_path / "v.html").read_text(errors="replace")
        assert token not in page and base64.b64encode(token.encode()).decode()[:24] not in page


@pytest.mark.parametrize("levels", [8, 16, 24])
def test_xacro_doubling_generators(levels, tmp_path, capfd):
    """Block properties and text properties that double at each level: refused in one line, at once."""
    blocks = ['<xacro:property name="b0"><link name="x"/></xacro:property>']
    blocks += [f'<xacro:property name="b{k}"><xacro:insert_block name="b{k - 1}"/>'
               f'<xacro:insert_block name="b{k - 1}"/></xacro:property>' for k in range(1, levels + 1)]
    texts = ['<xacro:property name="s0" value="abcdefgh"/>']
    texts += [f'<xacro:property name="s{k}" value="${{s{k - 1}}}${{s{k - 1}}}"/>' for k in range(1, levels + 1)]
    for body, tail in (("".join(blocks), f'<xacro:insert_block name="b{levels}"/>'),
                       ("".join(texts), f'<link name="${{s{levels}}}"/>')):
        path = tmp_path / "f.urdf.xacro"
        path.write_text('<?xml version="1.0"?><robot name="d" xmlns:xacro="http://www.ros.org/wiki/xacro">'
                        f"{body}{tail}</robot>")
        with no_hang(20):
            check_contract(["info", str(path)], capfd, [path])


# ------------------------------------------------------------------ round 3 (issue 33): new classes of input
#: More of every round-3 generator with SCREWKIN_FUZZ_SCALE=N (a campaign: N times CI's examples); the first
#: 20 of each run in the fast subset (conftest.FAST_MUTANTS), the rest in the slow tier.
SCALE = max(1, int(os.environ.get("SCREWKIN_FUZZ_SCALE", "1")))
MJCF_BASES = sorted((DATA / "mjcf").glob("*.xml"))
MJCF_MUTANTS = 60 * SCALE
ROUND3_MUTANTS = 160 * SCALE
EXPORT_MUTANTS = 40 * SCALE

def _op_mjcf_inertia(root, rng):
    """An <inertial> no body has, or one at the edge: negative, zero, A + B < C, a full tensor not positive."""
    elems = list(root.iter("inertial"))
    if not elems:
        return None
    e = rng.choice(elems)
    for k in ("diaginertia", "fullinertia"):
        e.attrib.pop(k, None)
    if rng.random() < 0.5:
        value = rng.choice(["1 1 2", "1 1 2.5", "1 1 -1", "0 0 0", "1e-5 1e-5 3e-5", "1 1 1", "nan 1 1", "1e308 1 1"])
        e.set("diaginertia", value)
        key = "diaginertia"
    else:
        value = rng.choice(["1 1 1 2 0 0", "1 1 1 0.5 0 0", "1 1 1 1 0 0", "2 2 2 0 0 0", "1 1 3 0 0 0"])
        e.set("fullinertia", value)
        key = "fullinertia"
    if rng.random() < 0.3:
        e.set("mass", rng.choice(["-1", "0", "1e-12", "1e7"]))
    return f"<inertial {key}> = {value!r}"


def _op_mjcf_limited(root, rng):
    """A joint's range with a limited flag MuJoCo knows (true, false, auto) or does not (yes, 1, '')."""
    joints = list(root.iter("joint"))
    if not joints:
        return None
    e = rng.choice(joints)
    flag = rng.choice(["true", "false", "auto", "yes", "1", ""])
    e.set("limited", flag)
    e.set("range", rng.choice(["-1 1", "1 -1", "-3.2 3.2", "0 0", "-1e308 1e308", "-90 90"]))
    return f"<joint {e.get('name')}> limited={flag!r} range={e.get('range')!r}"


def _op_mjcf_names(root, rng):
    """Names an export writes into comments or beside its own helper names: '--', '~F1', '~axis', 'world'."""
    named = [e for e in root.iter() if e.get("name")]
    if not named:
        return None
    e = rng.choice(named)
    old = e.get("name")
    loops = [c.get("name") for c in root.iter() if c.tag in ("connect", "weld", "loop_joint") and c.get("name")]
    new = rng.choice([f"{old}--x", f"{old}---x", f"{old}~F1", f"{old}~axis", "world", f"a--{old}", old + "-->",
                      "x" * 300] + [f"{n}~F1" for n in loops] + [f"{n}~axis" for n in loops])
    for other in root.iter():  # references follow the rename: the file stays consistent
        for key in ("body1", "body2", "joint", "joint1", "joint2", "site", "site1", "site2", "body"):
            if other.get(key) == old:
                other.set(key, new)
    e.set("name", new)
    return f"<{e.tag}> renamed {old!r} -> {new[:20]!r}"


def _op_mjcf_compiler(root, rng):
    comp = root.find("compiler")
    if comp is None:
        comp = ET.SubElement(root, "compiler")
    key, value = rng.choice([("angle", "degree"), ("angle", "radian"), ("angle", "grad"), ("eulerseq", "zyx"),
                             ("eulerseq", "abc"), ("autolimits", "false"), ("balanceinertia", "true")])
    comp.set(key, value)
    return f"<compiler {key}={value!r}>"


def _op_mjcf_equality(root, rng):
    eqs = [e for e in root.iter() if e.tag in ("connect", "weld", "joint")] if root.find("equality") is not None else []
    eqs = [e for e in eqs if e in list(root.find("equality"))]
    if not eqs:
        return None
    e = rng.choice(eqs)
    bodies = [b.get("name") for b in root.iter("body") if b.get("name")] + ["world", "ghost"]
    key = rng.choice(["body1", "body2", "anchor", "relpose", "polycoef", "active", "solref"])
    value = rng.choice(bodies) if key.startswith("body") else rng.choice(
        ["0 0 0", "nan 0 0", "1e308 0 0", "1 2", "0 0 0 1 0 0 0", "false", "0 1 0 0 0", ""])
    e.set(key, value)
    return f"<{e.tag} {key}> = {value!r}"


def _op_export_names(root, rng):
    """A link named as an export names its helpers ('LOOP~F1' bodies, 'LOOP~axis' connects) or with '--'."""
    loops = _names(root, "loop_joint")
    links = [e for e in root.iter("link") if e.get("name")]
    if not links:
        return None
    e = rng.choice(links)
    old = e.get("name")
    new = rng.choice([f"{n}~F1" for n in loops] + [f"{n}~axis" for n in loops] + [f"{old}---x", f"{old}--"])
    for other in root.iter():
        if other.get("link") == old:
            other.set("link", new)
    e.set("name", new)
    return f"link {old!r} renamed {new!r}"


EXPORT_URDF_OPS = TREE_OPS + [_op_export_names] * 6
MJCF_OPS = TREE_OPS[:2] + [_op_geometry, _op_delete, _op_duplicate, _op_move, _op_swap_names, _op_hostile_value,
                           _op_mjcf_inertia, _op_mjcf_inertia, _op_mjcf_limited, _op_mjcf_names, _op_mjcf_names,
                           _op_mjcf_compiler, _op_mjcf_equality, _op_mjcf_equality]


@functools.cache
def mjcf_mutant(i: int):
    """(base file, mutated bytes, description) of MJCF mutant i."""
    rng = random.Random(SEED * 11_000_027 + i)
    base = MJCF_BASES[i % len(MJCF_BASES)]
    data, what = _mutate(base.read_text(), rng, MJCF_OPS)
    return base, data, what


@pytest.mark.parametrize("i", range(MJCF_MUTANTS), ids=lambda i: f"mjcf-{i:03d}")
def test_mjcf_mutant(i, tmp_path, capfd):
    """MJCF files as MuJoCo reads them, mutated (inertias, limited flags, names an export writes, compiler
    settings, equalities): info, mobility, solve and dynamics keep the contract."""
    base, data, _ = mjcf_mutant(i)
    path = tmp_path / "m.xml"
    path.write_bytes(data)
    first = first_input(base)
    runs = [["info", str(path)], ["mobility", str(path), "--json"],
            ["solve", str(path), "--set", f"{first}=0.1", "--json", "--starts", "2"],
            ["dynamics", str(path), "--input", first, "--speed", "10rpm", "--steps", "4", "--json"]]
    for argv in runs:
        with no_hang(60):
            check_contract(argv, capfd, [path])


def _export_base(i):
    """A file to export: a bundled robot, an MJCF of tests/data, or a mutant of either."""
    kind = i % 4
    if kind == 0:
        return "urdf", ROBOTS / ["fourbar_crank_rocker.urdf", "rssr.urdf", "five_bar.urdf", "bennett.urdf",
                                 "slider_crank_offset.urdf", "spherical_fourbar.urdf"][(i // 4) % 6], None
    if kind == 1:
        return "mjcf", MJCF_BASES[(i // 4) % len(MJCF_BASES)], None
    if kind == 2:
        base, data, what = mjcf_mutant(i)
        return "mjcf", base, data
    rng = random.Random(SEED * 17_000_023 + i)
    base = BASES[i % len(BASES)]
    data, what = _mutate(base.read_text(), rng, EXPORT_URDF_OPS)
    return "urdf", base, data


@pytest.mark.parametrize("i", range(EXPORT_MUTANTS), ids=lambda i: f"export-{i:03d}")
def test_export_mutant(i, tmp_path, capfd):
    """export --mjcf and --urdf keep the contract, and what they write loads again: screwkin reads back its
    own export (exit 0, the same number of moving coordinates), MuJoCo compiles the MJCF."""
    fmt, base, data = _export_base(i)
    path = tmp_path / f"m{base.suffix}"
    if data is None:
        path.write_bytes(base.read_bytes())
    else:
        path.write_bytes(data)
    out_x, out_u = tmp_path / "out.xml", tmp_path / "out.urdf"
    with no_hang(60):
        code, _, err = check_contract(["export", str(path), "--mjcf", str(out_x), "--urdf", str(out_u), "--json"],
                                      capfd, [path], full=True)
    if code != 0:
        assert not out_x.exists() and not out_u.exists(), f"a failed export (exit {code}) left a file written"
        return
    for out in (out_x, out_u):
        with no_hang(60):
            again = check_contract(["mobility", str(out), "--json"], capfd, [out])
        assert again == 0, f"screwkin cannot read back its own export {out.name} of {base.name}"
    mujoco = pytest.importorskip("mujoco")
    mujoco.MjModel.from_xml_path(str(out_x))  # (an inertia no body has is refused by the reader, never written)


#: Values for the round-3 slots: {u} a value with a unit, {p} a --point, {v} a number or count, {o} an output.
UNIT_VALUES = ["10rpm", "90deg/s", "1e308rpm", "30mm", "30 mm", "30MM", "1turn", "-90deg", "1e5rad", "1e6rad",
               "5e-324deg", "nanrpm", "inf deg", "deg", "10 rpm rpm", "10°", "1e3mm/s", "2kN", "0.5N*m", "10Nm", "",
               "1_0deg", "\u0661\u0660deg", "0", "-0rpm", "1e-320rpm", "2rad/s", "3m/s^2", "1in", "60 RPM"]
POINT_VALUES = ["P=coupler:0,0,0", "P=coupler:60mm,20mm", "P=coupler:1e308,0,0", "P=nolink:0,0,0",
                "P=coupler:nan,0,0", "P=:0,0,0", "=coupler:0,0,0", "P=coupler:0,0,0,0", "P=coupler:",
                "P=coupler:1e4,0,0", "P=coupler:10001,0,0", "P=coupler:30deg,0,0", "a\nb=coupler:0,0,0",
                "P=coupler:0;0;0", "P=ground:0,0,0", "P=coupler:-0,0,0", "P=coupler:1e-320,0,0", "P=rocker:0 0 0"]
NUMBER_VALUES = OPTION_VALUES + ["2", "10", "0.5", "1e-4", "0.51", "1e-320", "-5", "20000", "600000"]
OUTPUTS_3 = ["out.csv", "missing/out.csv", ".", "/dev/full", "/proc/screwkin-fuzz.csv", "{f}", "out.gif", "out.mp4",
             "=HYPERLINK(x).csv", "a\nb.csv", "out.png", "out.parquet", "out.xml", "{f}.yaml"]
#: Command lines of the round-3 classes: dynamics options, export targets, unit strings, points, animations,
#: streamed sweeps, output paths.  {f} is a copy of the four-bar in the test's folder (an output may name it).
ROUND3_LINES = [
    ["dynamics", "{f}", "--input", "crank_joint", "--speed", "{u}", "--steps", "4"],
    ["dynamics", "{f}", "--input", "crank_joint", "--speed", "10rpm", "--steps", "4", "--cs", "{v}"],
    ["dynamics", "{f}", "--input", "crank_joint", "--speed", "10rpm", "--steps", "{v}"],
    ["dynamics", "{f}", "--input", "crank_joint", "--speed", "10rpm", "--steps", "4", "--gravity", "0,{v},-9.81"],
    ["dynamics", "{f}", "--input", "crank_joint", "--speed", "10rpm", "--steps", "4", "--load", "coupler:{u},0,0,0,0,0"],
    ["dynamics", "{f}", "--input", "crank_joint", "--speed", "10rpm", "--steps", "4", "--from", "{u}", "--to", "1"],
    ["dynamics", "{f}", "--input", "crank_joint", "--speed", "10rpm", "--steps", "4", "--point", "{p}", "--load",
     "P:1,0,0,0,0,0"],
    ["dynamics", "{f}", "--input", "crank_joint", "--speed", "10rpm", "--steps", "4", "--csv", "{o}", "--plot", "{o}"],
    ["dynamics", "{f}", "--input", "crank_joint", "--speed", "10rpm", "--steps", "4", "--set", "crank_joint={u}"],
    ["export", "{f}", "--mjcf", "{o}"],
    ["export", "{f}", "--urdf", "{o}", "--mjcf", "out.xml"],
    ["export", "{f}", "--mjcf", "{o}", "--urdf", "{o}"],
    ["export", "{f}", "--urdf", "out.urdf", "--set", "crank_joint={u}", "--near", "rocker_joint={u}"],
    ["solve", "{f}", "--set", "crank_joint={u}", "--json"],
    ["solve", "{f}", "--set", "crank_joint=0.5", "--rate", "crank_joint={u}", "--json"],
    ["solve", "{f}", "--set", "crank_joint=0.5", "--point", "{p}", "--json"],
    ["sweep", "{f}", "--input", "crank_joint", "--from", "{u}", "--to", "1", "--steps", "3"],
    ["sweep", "{f}", "--input", "crank_joint", "--from", "0", "--to", "1", "--steps", "3", "--point", "{p}"],
    ["view", "{f}", "--html", "out.html", "--sweep", "crank_joint=0:{u}:3"],
    ["map", _FIVE, "--x", "motor1=0:{u}:3", "--y", "motor2=0:1:3", "--json"],
    ["draw", "{f}", "--png", "out.png", "--point", "{p}", "--trace", "P", "--steps", "24"],
    ["draw", "{f}", "--png", "out.png", "--near", "{p}", "--set", "crank_joint={u}"],
    ["draw", "{f}", "--animate", "{o}", "--from", "0", "--to", "1", "--steps", "3"],
    ["draw", "{f}", "--animate", "out.gif", "--from", "0", "--to", "{u}", "--steps", "3"],
    ["draw", "{f}", "--animate", "out.gif", "--from", "0", "--to", "1", "--steps", "{v}", "--fps", "{v}"],
    ["draw", "{f}", "--animate", "out.gif", "--from", "0", "--to", "1", "--steps", "2", "--point", "{p}"],
    ["sweep", "{f}", "--input", "crank_joint", "--from", "0", "--to", "1", "--steps", "{v}", "--chunk", "{v}",
     "--csv", "s.csv"],
    ["sweep", "{f}", "--input", "crank_joint", "--from", "0", "--to", "360deg", "--steps", "30000", "--chunk", "7000",
     "--csv", "{o}"],
    ["sweep", "{f}", "--input", "crank_joint", "--from", "0", "--to", "360deg", "--steps", "30000", "--chunk", "7000",
     "--parquet", "{o}", "--csv", "{o}"],
    ["sweep", "{f}", "--input", "crank_joint", "--from", "0", "--to", "1", "--steps", "3", "--csv", "{o}", "--plot",
     "{o}"],
    ["report", "{f}", "--no-view", "--md", "{o}"],
    ["view", "{f}", "--html", "{o}"],
]


@functools.cache
def round3_line(i: int):
    rng = random.Random(SEED * 13 + i)
    template = ROUND3_LINES[i % len(ROUND3_LINES)]
    slots = {"{u}": rng.choice(UNIT_VALUES), "{p}": rng.choice(POINT_VALUES), "{v}": rng.choice(NUMBER_VALUES),
             "{o}": rng.choice(OUTPUTS_3)}
    out = []
    for a in template:
        for k, v in slots.items():
            a = a.replace(k, v)
        out.append(a)
    return out


@pytest.mark.parametrize("i", range(ROUND3_MUTANTS), ids=lambda i: f"r3-{i:03d}")
def test_round3_command_mutant(i, tmp_path, capfd, monkeypatch):
    """The round-3 command lines keep the contract (exit 0, 1 or 2, one error line, no traceback, bounded
    time), and never write over the model they read nor leave anything in /proc."""
    monkeypatch.chdir(tmp_path)
    model = tmp_path / "fourbar.urdf"
    model.write_text((ROBOTS / "fourbar_crank_rocker.urdf").read_text())
    before = model.read_bytes()
    argv = [a.replace("{f}", str(model)) for a in round3_line(i)]
    with no_hang(90):
        check_contract(argv, capfd, [model, _FIVE])
    assert model.read_bytes() == before, "the model was written over"
    assert not any(name.startswith("screwkin-fuzz") for name in os.listdir("/proc"))


_UNIT_TEXT = st.lists(st.sampled_from(list("0123456789.-+e E") + ["deg", "rad", "rpm", "mm", "m", "/s", "^2", "turn",
                                                                   "°", "N", "k", "in", "\u0661"]),
                      max_size=10).map("".join)


@settings(max_examples=40 * SCALE, deadline=None, database=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(_UNIT_TEXT, st.sampled_from(["--set crank_joint={}", "--rate crank_joint={}", "--near rocker_joint={}"]))
def test_unit_strings_through_the_options(tmp_path, capfd, text, option):
    """Any string of digits, signs and unit pieces typed as a value, a rate or a --near value: the contract,
    and a value accepted is finite."""
    flag, value = option.split(" ")
    argv = ["solve", _FOURBAR, "--set", "crank_joint=0.5", flag, value.format(text), "--json", "--starts", "0"]
    if flag == "--set":
        argv = ["solve", _FOURBAR, flag, value.format(text), "--json", "--starts", "0"]
    with no_hang(60):
        check_contract(argv, capfd, [_FOURBAR])
