"""Survey screwkin on MuJoCo Menagerie's models as published, with MuJoCo as the oracle.

Run:  python examples/menagerie_survey.py PATH/TO/mujoco_menagerie [--only NAME,...] [--json OUT.json]

Menagerie is not shipped with screwkin (its files are under their own licences); give the path of
a local checkout.  For every robot file of it (``*.xml`` with a ``<mujoco>`` root and a body, the
``scene*`` files and included fragments left out) the model folder is copied into a temporary
folder with every mesh, texture and height field the model names replaced by a primitive stand-in
(a 2 cm box, a 1-pixel picture): the XML is not changed, so MuJoCo and screwkin read the same text.
Then, for each model:

- ``loads``: screwkin reads it (``info``); else the one-line error;
- ``M``, ``nv-rank``: screwkin's mobility and MuJoCo's nv minus the rank of its equality rows
  (efc_J at qpos0, contacts, limits and friction loss disabled);
- ``pos``: the largest distance between a body's position in MuJoCo (mj_forward at qpos0) and in
  screwkin at the same joint values [m];
- ``export``: ``screwkin export --mjcf`` loads in MuJoCo and runs 1 s (mj_step, the file's
  timestep) with 0.05 N m (or N) on every motor, without a MuJoCo warning and with finite
  qpos and qvel.

It ends with the tally: loaded, mobility equal to MuJoCo's, body positions within 1e-9 m, exports
that simulate.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import shutil
import struct
import sys
import tempfile
import zlib
from pathlib import Path

import numpy as np

import screwkin
from screwkin.cli import main as screwkin_main

try:
    import mujoco
except ImportError:  # the survey still runs screwkin, without the oracle
    mujoco = None

#: A 2 cm cube as a binary STL (12 triangles) and as OBJ text: what every mesh file becomes.
_CUBE = [(x, y, z) for x in (-0.01, 0.01) for y in (-0.01, 0.01) for z in (-0.01, 0.01)]
_FACES = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1), (2, 3, 7), (2, 7, 6), (0, 2, 6),
          (0, 6, 4), (1, 5, 7), (1, 7, 3)]


def _png() -> bytes:
    """A 2 x 2 grey PNG, for textures and height fields."""
    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))
    rows = b"".join(b"\0" + b"\x80\x80\x80" * 2 for _ in range(2))
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", 2, 2, 8, 2, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b""))


def _stl() -> bytes:
    out = bytearray(80) + struct.pack("<I", len(_FACES))
    for f in _FACES:
        out += struct.pack("<3f", 0, 0, 0)
        for i in f:
            out += struct.pack("<3f", *_CUBE[i])
        out += b"\0\0"
    return bytes(out)


def _obj() -> bytes:
    lines = [f"v {x} {y} {z}" for x, y, z in _CUBE] + [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in _FACES]
    return ("\n".join(lines) + "\n").encode()


def _stand_in(path: Path) -> None:
    suffix = path.suffix.lower()
    path.parent.mkdir(parents=True, exist_ok=True)
    if suffix == ".stl":
        path.write_bytes(_stl())
    elif suffix == ".obj":
        path.write_bytes(_obj())
    elif suffix == ".png":
        path.write_bytes(_png())
    else:  # .msh and others: MuJoCo's own formats are not faked; the model is reported as not loaded
        path.write_bytes(b"")


def robot_files(root: Path) -> list:
    """The robot files of a checkout: <mujoco> files with a <body> that no other file includes."""
    files = sorted(p for p in root.glob("*/*.xml") if not p.name.startswith("scene"))
    out = []
    for p in files:
        text = p.read_text(errors="replace")
        if "<mujoco" in text and "<body" in text:
            out.append(p)
    included = set()
    for p in files:
        for other in out:
            if f'file="{other.name}"' in p.read_text(errors="replace") and p.parent == other.parent:
                included.add(other)
    return [p for p in out if p not in included]


def stand_in_copy(path: Path, into: Path) -> Path:
    """The model's folder copied (XML only) into ``into``, its assets replaced by stand-ins."""
    dest = into / path.parent.name
    shutil.copytree(path.parent, dest, ignore=lambda d, names: [n for n in names if not (
        n.endswith(".xml") or (Path(d) / n).is_dir())])
    copy = dest / path.name
    if mujoco is None:
        return copy
    spec = mujoco.MjSpec.from_file(str(copy))
    meshdir = dest / (spec.meshdir or "")
    texdir = dest / (spec.texturedir or "")
    for m in spec.meshes:
        if m.file:
            _stand_in(meshdir / m.file)
    for t in spec.textures:
        for f in [t.file, *list(getattr(t, "cubefiles", []) or [])]:
            if f:
                _stand_in(texdir / f)
    for h in spec.hfields:
        if h.file:
            _stand_in(dest / h.file)
    return copy


def mujoco_answers(path: Path):
    """(model, data, nv - rank of the equality rows) at qpos0."""
    m = mujoco.MjModel.from_xml_path(str(path))
    m.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CONTACT | mujoco.mjtDisableBit.mjDSBL_LIMIT
                              | mujoco.mjtDisableBit.mjDSBL_FRICTIONLOSS)
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    J = d.efc_J.reshape(d.nefc, m.nv)[:d.ne] if d.nefc else np.zeros((0, m.nv))
    return m, d, m.nv - (np.linalg.matrix_rank(J, tol=1e-9) if J.size else 0)


def joint_name(m, j) -> str:
    """MuJoCo's joint j by its name, or by the name screwkin gives an unnamed joint (BODY_jointK,
    K its place among the body's joints)."""
    name = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, j)
    if name:
        return name
    b = m.jnt_bodyid[j]
    return f"{mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, b)}_joint{j - m.body_jntadr[b]}"


def screwkin_q(mech, m, qpos):
    """screwkin's configuration for MuJoCo's qpos (hinge, slide: the value; ball: (w,x,y,z) ->
    (x,y,z,w); free: the pose relative to the body's own at qpos0)."""
    import pinocchio as pin
    q = np.zeros(mech.nq)
    coupled = {c.joint for c in mech.couplings}
    for j in range(m.njnt):
        name = joint_name(m, j)
        adr, t = m.jnt_qposadr[j], int(m.jnt_type[j])
        if name in coupled:
            continue
        c = mech.coordinate(name)
        if t in (int(mujoco.mjtJoint.mjJNT_HINGE), int(mujoco.mjtJoint.mjJNT_SLIDE)):
            q[c.idx_q] = qpos[adr]
        elif t == int(mujoco.mjtJoint.mjJNT_BALL):
            w, x, y, z = qpos[adr:adr + 4]
            q[c.idx_q:c.idx_q + 4] = (x, y, z, w)
        else:
            b = m.jnt_bodyid[j]
            X0 = pin.XYZQUATToSE3(np.r_[m.body_pos[b], m.body_quat[b][[1, 2, 3, 0]]])
            W = pin.XYZQUATToSE3(np.r_[qpos[adr:adr + 3], qpos[adr + 4:adr + 7], qpos[adr + 3]])
            q[c.idx_q:c.idx_q + 7] = pin.SE3ToXYZQUAT(X0.inverse() * W)
    return q


def position_error(mech, m, d) -> float:
    """The largest distance between a body's world position in MuJoCo and in screwkin [m]."""
    import pinocchio as pin
    q = screwkin_q(mech, m, d.qpos)
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, q)
    err = 0.0
    for b in range(1, m.nbody):
        name = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, b)
        if name is None or name not in mech.spec.links:
            continue
        err = max(err, float(np.linalg.norm(data.oMf[mech.link_frame(name)].translation - d.xpos[b])))
    return err


def simulates(path: Path, seconds: float = 1.0, effort: float = 0.05):
    """(ok, why) of 1 s of MuJoCo's simulation of an exported file with ``effort`` on every motor."""
    m = mujoco.MjModel.from_xml_path(str(path))
    d = mujoco.MjData(m)
    d.ctrl[:] = effort
    if not m.nu and m.nv:
        d.qfrc_applied[0] = effort
    for _ in range(int(round(seconds / m.opt.timestep))):
        mujoco.mj_step(m, d)
    warned = [mujoco.mjtWarning(k).name for k in range(len(d.warning)) if d.warning[k].number]
    if warned:
        return False, "warnings " + ", ".join(warned)
    if not (np.all(np.isfinite(d.qpos)) and np.all(np.isfinite(d.qvel))):
        return False, "qpos or qvel not finite"
    return True, ""


def survey(path: Path, work: Path) -> dict:
    row = {"model": f"{path.parent.name}/{path.name}"}
    copy = stand_in_copy(path, work)
    m = d = None
    if mujoco is not None:
        try:
            m, d, nv_rank = mujoco_answers(copy)
            row["mujoco"] = int(nv_rank)
        except Exception as exc:  # noqa: BLE001 - a survey row, not a crash
            row["mujoco_error"] = str(exc).splitlines()[0][:120]
    try:
        mech = screwkin.load(copy, warn=lambda w: None)
    except screwkin.MechanismFileError as exc:
        row["error"] = str(exc).split(": ", 1)[-1][:160]
        return row
    row["loads"] = True
    try:
        row["M"] = mech.mobility().mobility
    except Exception as exc:  # noqa: BLE001 - a survey row, not a crash
        row["error"] = f"mobility: {str(exc)[:140]}"
        return row
    if m is not None:
        try:
            row["pos"] = position_error(mech, m, d)
        except Exception as exc:  # noqa: BLE001 - a survey row, not a crash
            row["pos_error"] = str(exc)[:120]
    out = work / (path.stem + ".export.xml")
    err = io.StringIO()
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
        rc = screwkin_main(["export", str(copy), "--mjcf", str(out)])
    if rc != 0:
        row["export_error"] = err.getvalue().strip().splitlines()[-1][:160] if err.getvalue().strip() else f"exit {rc}"
    elif mujoco is not None:
        try:
            row["simulates"], why = simulates(out)
            if why:
                row["export_error"] = why
        except Exception as exc:  # noqa: BLE001 - a survey row, not a crash
            row["export_error"] = f"MuJoCo: {str(exc).splitlines()[0][:120]}"
    return row


def line(row) -> str:
    """One printed line of a survey row."""
    same = row.get("M") is not None and row.get("M") == row.get("mujoco")
    pos = f"{row['pos']:.1e}" if "pos" in row else "-"
    why = " | ".join(row[k] for k in ("error", "mujoco_error", "pos_error", "export_error") if k in row)
    return (f"{row['model']:48s} {'loads' if row.get('loads') else 'refused':7s} M {row.get('M', '-')!s:>3s} "
            f"MuJoCo {row.get('mujoco', '-')!s:>3s} {'=' if same else ' '} pos {pos:7s} "
            f"export {'simulates' if row.get('simulates') else '-':9s} {why}")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("menagerie", type=Path)
    ap.add_argument("--only", help="model folders to survey, comma separated")
    ap.add_argument("--json", type=Path, help="write the rows here")
    args = ap.parse_args(argv)
    files = robot_files(args.menagerie)
    if args.only:
        keep = set(args.only.split(","))
        files = [f for f in files if f.parent.name in keep]
    if not files:
        print(f"no robot files under {args.menagerie}", file=sys.stderr)
        return 1
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for k, f in enumerate(files):
            work = Path(tmp) / str(k)
            work.mkdir()
            row = survey(f, work)
            rows.append(row)
            print(line(row), flush=True)
    n = len(rows)
    with_mj = [r for r in rows if "mujoco" in r]
    tally = {
        "models": n,
        "mujoco_loads": len(with_mj),
        "screwkin_loads": sum(1 for r in rows if r.get("loads")),
        "mobility_equal": sum(1 for r in with_mj if r.get("M") == r["mujoco"]),
        "positions_1e-9": sum(1 for r in rows if r.get("pos", 1.0) < 1e-9),
        "export_simulates": sum(1 for r in rows if r.get("simulates")),
    }
    print("tally: " + ", ".join(f"{k} {v}" for k, v in tally.items()))
    if args.json:
        args.json.write_text(json.dumps({"rows": rows, "tally": tally}, indent=1, default=float))
    return 0


if __name__ == "__main__":
    sys.exit(main())
