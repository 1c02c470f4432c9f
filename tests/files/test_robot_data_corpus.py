"""Every URDF of example-robot-data (the PyPI package, when installed): info, mobility and export
--mjcf, with MuJoCo as the oracle on the export: its nv - rank of the equality rows equals screwkin's
mobility, and its bodies stand where screwkin puts the links at the written configuration (qpos0),
to 1e-9 m.  Slow: 69 robots, some of 100 links."""

import contextlib
import io

import numpy as np
import pinocchio as pin
import pytest

import screwkin
from screwkin.cli import main
from conftest import ROBOT_DATA

mujoco = pytest.importorskip("mujoco")
pytestmark = [pytest.mark.slow,
              pytest.mark.skipif(ROBOT_DATA is None, reason="example-robot-data is not installed")]
URDFS = sorted(ROBOT_DATA.rglob("*.urdf")) if ROBOT_DATA is not None else []


@pytest.mark.parametrize("path", URDFS, ids=lambda p: p.name)
def test_robot_data_urdf(tmp_path, path):
    out = tmp_path / "export.xml"
    if "<link" not in path.read_text():  # ur3.urdf: an empty <robot> (the xacro macros' file, expanded)
        err = io.StringIO()
        with contextlib.redirect_stderr(err):
            assert main(["info", str(path)]) == 1
        assert "the file has no links" in err.getvalue()
        return
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        assert main(["info", str(path)]) == 0
        mech = screwkin.load(path, warn=lambda w: None)
        M = mech.mobility().mobility
        assert main(["export", str(path), "--mjcf", str(out)]) == 0
    m = mujoco.MjModel.from_xml_path(str(out))
    m.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CONTACT | mujoco.mjtDisableBit.mjDSBL_LIMIT
                              | mujoco.mjtDisableBit.mjDSBL_FRICTIONLOSS)
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    J = d.efc_J.reshape(d.nefc, m.nv)[:d.ne]
    assert m.nv - (np.linalg.matrix_rank(J, tol=1e-9) if J.size else 0) == M
    q = mech.generic_configurations()[0].q  # the written file's zero
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, q)
    for b in range(1, m.nbody):
        name = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, b)
        if name in mech.spec.links:
            np.testing.assert_allclose(d.xpos[b], data.oMf[mech.link_frame(name)].translation, rtol=0, atol=1e-9)
