"""Sweep plots (issue 17 part 4): angles unwrapped and in degrees, lengths in mm on their own axis,
a legend entry for every curve, the located singularities and limit positions marked, a title
naming the mechanism and the input."""

import numpy as np
import pytest

import screwkin
from conftest import ROBOTS
from screwkin.analysis.position.position import PositionSolver
from screwkin.analysis.motion.singular_points import locate_singularities
from screwkin.analysis.motion.sweep import sweep
from screwkin.cli import main

pytest.importorskip("matplotlib")
from screwkin.present.plots import sweep_figure  # noqa: E402


def _lines(ax):
    return [ln for ln in ax.get_lines() if ln.get_label() and not ln.get_label().startswith("_")]


def test_non_grashof_limits_marked_and_every_curve_in_the_legend():
    mech = screwkin.load(ROBOTS / "fourbar_non_grashof.urdf")
    solver = PositionSolver(mech, ["input_joint"])
    res = sweep(solver, "input_joint", 0.0, np.radians(350), 120, turn=True)
    sing = locate_singularities(solver, res)
    limits = [s for s in sing if s.limit]
    assert len(limits) == 2  # the rocker's two limit positions
    mus = np.linspace(0.2, 1.0, len(res.values))
    fig = sweep_figure(res, mus, sing, title="fourbar_non_grashof.urdf: input_joint", linear=mech.translational)
    axes = fig.axes
    top = axes[0]
    labels = [t.get_text() for t in top.get_legend().get_texts()]
    # one entry per coordinate, the transmission angle and the limit position marker
    assert labels == [f"{n} [deg]" for n in res.names] + ["transmission angle [deg]", "limit position"]
    curves = [ln for ln in _lines(top) if np.size(ln.get_xdata()) > 2]
    assert len(curves) == len(res.names) + 1
    # the markers: vertical lines at the located inputs, in degrees on the unwrapped axis
    verticals = sorted({float(ln.get_xdata()[0]) for ln in top.get_lines() if np.ptp(np.asarray(ln.get_xdata(), float)) == 0})
    expected = sorted(float(np.degrees(s.input)) for s in limits)
    xs = np.asarray(curves[0].get_xdata())
    assert len(verticals) == len(expected) == 2  # one marker per limit position, no more, no fewer
    for v, e in zip(verticals, expected, strict=True):
        assert abs((v - e + 180) % 360 - 180) < 1e-6  # the same angle
        assert xs.min() - 3 <= v <= xs.max() + 3  # and on the plotted range (within a step of 2.9 deg)
    # degrees: the input's own curve is the x axis itself
    np.testing.assert_allclose(curves[0].get_ydata(), xs, atol=1e-9)
    assert axes[2].get_xlabel() == "input input_joint [deg]"
    assert fig._suptitle.get_text() == "fourbar_non_grashof.urdf: input_joint"
    for ax in axes[:3]:  # every row's legend has an entry for every curve it draws
        assert len(ax.get_legend().get_texts()) >= len(res.names)


def test_angles_unwrapped_and_lengths_in_mm():
    mech = screwkin.load(ROBOTS / "slider_crank_offset.urdf")
    solver = PositionSolver(mech, ["crank_joint"])
    res = sweep(solver, "crank_joint", 0.0, np.radians(400), 80)
    fig = sweep_figure(res, linear=mech.translational)
    top, twin = fig.axes[0], fig.axes[3]  # the first row and its right axis (lengths)
    k = list(res.names).index("slider_joint")
    slider = [ln for ln in _lines(twin) if ln.get_label().startswith("slider_joint")][0]
    assert slider.get_label() == "slider_joint [mm]"
    np.testing.assert_allclose(slider.get_ydata(), 1000 * res.joints[:, k])
    assert twin.get_ylabel().endswith("[mm]") and top.get_ylabel() == "joint value [deg]"
    crank = [ln for ln in _lines(top) if ln.get_label().startswith("crank_joint")][0]
    y = crank.get_ydata()
    assert np.max(np.abs(np.diff(y))) < 10  # no jump of 360 deg: unwrapped
    assert y[-1] == pytest.approx(400, abs=1e-6)
    labels = [t.get_text() for t in top.get_legend().get_texts()]
    assert labels == [f"{n} [{'mm' if n == 'slider_joint' else 'deg'}]" for n in res.names]


def test_cli_plot_is_written(tmp_path):
    png = tmp_path / "s.png"
    assert main(["sweep", str(ROBOTS / "fourbar_non_grashof.urdf"), "--input", "input_joint", "--from", "0",
                 "--to", "350deg", "--turn", "--singularities", "--plot", str(png)]) == 0
    assert png.stat().st_size > 20000
