"""The pictures a newcomer found weak (issue 27 item 5): titles, axes in the units typed, blank
cells off the mapped mode drawn as a hatched region with a legend entry of their own."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import screwkin
from screwkin.analysis.singularities.maps import singularity_map

from conftest import screwkin_cli

pytest.importorskip("matplotlib")
ROBOTS = Path(__file__).resolve().parents[2] / "robots"


def test_map_png_is_titled_in_the_typed_units(wide_five_bar, tmp_path):
    from PIL import Image

    out = tmp_path / "map.png"
    p = screwkin_cli("map", str(wide_five_bar), "--x", "motor1=-180deg:180deg:13",
                     "--y", "motor2=-3.14159:-2.5:5", "--png", str(out))
    assert p.returncode == 0, p.stderr
    info = Image.open(out).info
    title = info["Title"]
    assert info["Description"] == "x: motor1 [deg]; y: motor2 [rad]"  # a bare angle is in radians
    assert "five_bar" in title and "motor1" in title and "motor2" in title


def test_map_figure_axes_legend_and_masked_cells(wide_five_bar):
    import matplotlib.pyplot as plt

    from screwkin.present.plots import map_figure

    mech = screwkin.load(wide_five_bar)
    xs = np.linspace(-np.pi, np.pi, 13)
    res = singularity_map(screwkin.PositionSolver(mech), "motor1", xs, "motor2", xs)
    assert (~res.reached).any() and res.reached.any()
    fig = map_figure(res, "deg", "deg", title="t")
    ax = fig.axes[0]
    assert ax.get_xlabel() == "motor1 [deg]" and ax.get_ylabel() == "motor2 [deg]"
    lo, hi = ax.get_xlim()  # degrees: 180 deg and half a 30 deg cell
    np.testing.assert_allclose([lo, hi], [-195.0, 195.0], rtol=0, atol=1e-9)
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert "not reached on this assembly mode" in labels
    mesh = next(c for c in ax.collections if hasattr(c, "get_array") and c.get_array() is not None
                and np.ma.getmaskarray(c.get_array()).size == res.reached.size)
    np.testing.assert_array_equal(np.ma.getmaskarray(mesh.get_array()).reshape(res.reached.shape), ~res.reached)
    plt.close(fig)


def test_map_seams_join_neighbours_on_different_sheets():
    """Around the five-bar's singular point the mode is two sheets: the elbow angles of two
    neighbouring cells differ by tens of degrees across a seam, by a few degrees elsewhere."""
    mech = screwkin.load(ROBOTS / "five_bar.urdf")
    xs = np.radians(np.linspace(-60, 200, 21))
    ys = np.radians(np.linspace(-160, 100, 21))
    res = singularity_map(screwkin.PositionSolver(mech), "motor1", xs, "motor2", ys)
    assert len(res.seams) > 0 and any("seam" in n for n in res.notes)
    from screwkin.present.report import map_dict

    assert map_dict(res)["seams"] == res.seams.tolist()
    names = mech.coordinate_names
    elbows = [names.index("elbow1"), names.index("elbow2")]
    for j, i, j2, i2 in res.seams:
        d = np.angle(np.exp(1j * (res.q[j, i, elbows] - res.q[j2, i2, elbows])))
        assert np.abs(d).max() > 0.3  # rad: 17 deg, where a 13 deg input step moves an elbow less


def _panda():
    from conftest import ROBOT_DATA

    if ROBOT_DATA is None:
        pytest.skip("example-robot-data is not installed (pip install example-robot-data)")
    return ROBOT_DATA / "panda_description" / "urdf" / "panda.urdf"


def test_panda_legend_says_no_actuation_is_declared():
    """example-robot-data's panda.urdf has no <transmission>: its motors are not 'passive joints'."""
    from screwkin.present.view import build_scene, legend_entries

    path = _panda()
    assert "<transmission" not in path.read_text()
    mech = screwkin.load(str(path), warn=lambda _: None)
    labels = [label for label, _ in legend_entries(build_scene(mech, mech.assemble().q, warn=lambda _: None))]
    assert "joints (no actuation declared)" in labels and "passive joints" not in labels
    mech.set_actuated(["panda_joint1"])  # declared on the command line: the others are passive again
    labels = [label for label, _ in legend_entries(build_scene(mech, mech.assemble().q, warn=lambda _: None))]
    assert "actuated joints" in labels and "passive joints" in labels


@pytest.fixture(scope="module")
def small_study():
    """Four-bars with the crank typed in mm: one not assembled (ground 0.5 m > 0.04 + 0.12 + 0.08)."""
    from screwkin.parallel.study import run_study

    spec = {"file": str(ROBOTS / "fourbar.urdf.xacro"), "input": "crank_joint", "output": "rocker",
            "parameters": {"crank": {"values": ["20mm", "40mm"]}, "ground": {"values": [0.1, 0.5]}},
            "metrics": ["grashof", "transmission_angle"], "transmission": {"steps": 12},
            "pareto": {"maximize": ["transmission_angle_min_deg", "grashof_margin"]}}
    return run_study(spec, workers=0)


def test_study_metrics_plot_has_units_and_colours_by_class_and_failure(small_study):
    import matplotlib.colors as mcolors
    import matplotlib.pyplot as plt

    from screwkin.present.study import FAILED_COLOR, metrics_figure

    res = small_study
    assert res.failed and res.succeeded
    fig = metrics_figure(res)
    axes = fig.axes
    assert axes[-2].get_xlabel() == "crank [mm]"
    assert axes[-1].get_xlabel().startswith("ground (as given")
    ylabels = {ax.get_ylabel() for ax in axes if ax.get_ylabel()}
    assert {"Grashof margin (p+q)-(s+l) [mm]", "smallest transmission angle [deg]"} <= ylabels
    crank_margin = axes[0]  # first row: grashof_margin against crank
    assert crank_margin.get_ylabel().startswith("Grashof margin")
    lines = {line.get_label(): line for line in crank_margin.get_lines()}
    fails = lines["failed"]
    np.testing.assert_allclose(sorted(fails.get_xdata()), sorted(1000 * r["crank"] for r in res.failed), rtol=0,
                               atol=1e-9)
    assert mcolors.same_color(fails.get_color(), FAILED_COLOR)
    for cls in {r["grashof"] for r in res.succeeded}:
        rows = [r for r in res.succeeded if r["grashof"] == cls]
        # the margin (p + q) - (s + l) of a four-bar with links 0.1 (ground), crank, 0.12, 0.08 -- in mm
        want = sorted(1000 * (sum(ls) - 2 * (min(ls) + max(ls)))  # p + q = sum - (s + l)
                      for ls in ([r["ground"], r["crank"], 0.12, 0.08] for r in rows))
        np.testing.assert_allclose(sorted(lines[cls].get_ydata()), want, rtol=0, atol=1e-6)
    legend = [t.get_text() for t in fig.legends[0].get_texts()]
    assert "failed" in legend and set(legend) >= {r["grashof"] for r in res.succeeded}
    plt.close(fig)


def test_study_pareto_plot_has_units_and_counts_the_failed(small_study):
    import matplotlib.pyplot as plt

    from screwkin.present.study import pareto_figure

    fig = pareto_figure(small_study)
    ax = fig.axes[0]
    assert ax.get_xlabel() == "smallest transmission angle [deg] (maximize)"
    assert ax.get_ylabel() == "Grashof margin (p+q)-(s+l) [mm] (maximize)"
    assert f"{len(small_study.failed)} failed (not drawn)" in ax.get_title()
    assert ax.get_legend().get_title().get_text() == "Grashof class"
    plt.close(fig)


def test_stewart_workspace_slices_are_readable():
    """Three slices of the Gough-Stewart platform's workspace in mm: each panel's image holds the
    conditioning of the reached grid points of its slice, at their coordinates."""
    import matplotlib.pyplot as plt

    from screwkin.analysis.design.workspace import workspace
    from screwkin.present.workspace import workspace_figure

    mech = screwkin.load(ROBOTS / "gough_stewart_6ups.urdf")
    r = workspace(mech, "platform", resolution=0.1)
    assert r.dimension == 3
    fig = workspace_figure(r)
    panels = [ax for ax in fig.axes if ax.get_images()]
    assert len(panels) == 3
    assert [(ax.get_xlabel(), ax.get_ylabel()) for ax in panels] == [("x [mm]", "y [mm]"), ("x [mm]", "z [mm]"),
                                                                     ("y [mm]", "z [mm]")]
    centre = np.round(np.mean(r.index, axis=0)).astype(int)
    for ax, n in zip(panels, (2, 1, 0)):
        at = 1000 * (r.origin[n] + centre[n] * r.resolution)  # the grid's axes are the world's for a 3-D grid
        assert ax.get_title() == f"slice {'xyz'[n]} = {at:.1f} mm"
        shown = ax.get_images()[0].get_array()
        sel = r.index[:, n] == centre[n]
        np.testing.assert_allclose(np.sort(shown.compressed()), np.sort(r.measures["conditioning"][sel]), rtol=0,
                                   atol=0)
        lo, hi = ax.get_xlim()  # the slice fits its panel: every reached point of it inside, in mm
        a = (0, 0, 1)[(2, 1, 0).index(n)]
        assert lo < 1000 * r.positions[sel, a].min() and 1000 * r.positions[sel, a].max() < hi
    assert fig.legends and "boundary (located)" in [t.get_text() for t in fig.legends[0].get_texts()]
    assert "gough_stewart_6ups" in fig._suptitle.get_text()
    plt.close(fig)


def test_a_volume_axis_has_the_designs_dimension():
    from types import SimpleNamespace

    from screwkin.present.study import _label

    planar = SimpleNamespace(succeeded=({"workspace_dimension": 2},) * 3)
    mixed = SimpleNamespace(succeeded=({"workspace_dimension": 2}, {"workspace_dimension": 3}))
    assert _label("workspace_volume", planar) == ("workspace volume [m^2]", 1.0)
    assert _label("singularity_free_volume", mixed)[0] == "singularity-free volume [m^d]"
