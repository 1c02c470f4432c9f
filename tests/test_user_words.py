"""What a new user trips on (issue 43 items 5-8): the unit typed is the unit shown (tables, plots, reports),
words that say what they measure, one lettering, one parse of counts, an answer that fits a screen with the
explanations behind --explain, and when --workers helps."""

from __future__ import annotations

import math

import pytest

from conftest import ROBOTS
from screwkin.cli import main

FOURBAR = str(ROBOTS / "fourbar_crank_rocker.urdf")


def _out(argv, capsys, code=0):
    got = main(argv)
    out, err = capsys.readouterr()
    assert got == code, err
    return out, err


# ------------------------------------------------------------------ item 5: units
def _captured_figures(monkeypatch, module):
    """The matplotlib figures ``module`` would write, kept (the plot is checked, not its pixels)."""
    figures = []
    monkeypatch.setattr(module, "write_figure", lambda fig, path, **kw: figures.append(fig))
    return figures


def _curve(fig, row_word, name):
    ax = next(a for a in fig.axes if row_word in a.get_ylabel())
    line = next(ln for ln in ax.get_lines() if ln.get_label().startswith(name))
    return ax, line


def test_sweep_plot_draws_rates_in_the_rpm_typed(tmp_path, monkeypatch, capsys):
    """--rate 120rpm: the text table says rpm, so does the plot -- the crank's omega is 120 (the rate typed),
    not 720 deg/s, and alpha is in rpm/s."""
    pytest.importorskip("matplotlib")
    import screwkin.present.plots as plots

    figures = _captured_figures(monkeypatch, plots)
    out, _ = _out(["sweep", FOURBAR, "--input", "crank_joint", "--from", "40deg", "--to", "400deg", "--steps", "12",
                   "--rate", "120rpm", "--plot", str(tmp_path / "s.png")], capsys)
    assert "omega crank [rpm]" in out
    (fig,) = figures
    ax, crank = _curve(fig, "omega", "crank")
    assert ax.get_ylabel().endswith("[rpm]") and crank.get_label().endswith("[rpm]")
    assert list(crank.get_ydata()) == pytest.approx([120.0] * 13)
    ax, _ = _curve(fig, "alpha", "rocker")
    assert ax.get_ylabel().endswith("[rpm/s]")


def test_sweep_plot_draws_deg_per_s_typed_and_keeps_its_default(tmp_path, monkeypatch, capsys):
    pytest.importorskip("matplotlib")
    import screwkin.present.plots as plots

    figures = _captured_figures(monkeypatch, plots)
    for rate in (["--rate", "90deg/s"], []):
        _out(["sweep", FOURBAR, "--input", "crank_joint", "--from", "0", "--to", "90deg", "--steps", "3", *rate,
              "--plot", str(tmp_path / "s.png")], capsys)
    typed, default = figures
    _, crank = _curve(typed, "omega", "crank")
    assert crank.get_label().endswith("[deg/s]") and list(crank.get_ydata()) == pytest.approx([90.0] * 4)
    _, crank = _curve(default, "omega", "crank")  # per 1 rad/s of the input, drawn in deg/s as before
    assert list(crank.get_ydata()) == pytest.approx([math.degrees(1.0)] * 4)


def test_report_sweeps_in_the_rpm_typed(tmp_path, monkeypatch, capsys):
    """report --rate crank_joint=120rpm: the sweep section says 120 rpm (not 12.5664 rad/s) and its figure draws
    omega in rpm."""
    pytest.importorskip("matplotlib")
    import screwkin.commands.report as report

    figures = []
    real = report.motion_figure
    monkeypatch.setattr(report, "motion_figure", lambda *a, **k: figures.append(real(*a, **k)) or figures[-1])
    md = tmp_path / "r.md"
    _out(["report", FOURBAR, "--set", "crank_joint=40deg", "--rate", "crank_joint=120rpm", "--md", str(md),
          "--no-view", "--steps", "24"], capsys)
    text = md.read_text()
    line = next(ln for ln in text.splitlines() if ln.startswith("crank_joint moved"))
    assert "120 rpm" in line and "rad/s" not in line and "from 40 deg" in line
    (fig,) = figures
    _, crank = _curve(fig, "omega", "crank")
    assert list(crank.get_ydata()) == pytest.approx([120.0] * len(crank.get_ydata()))
