"""present/numtext writes '%.12g' for whole arrays in numpy: every value's text must be Python's
own ``'%.12g' % x`` (the oracle), and a sweep's CSV the rows ``"%d,%.12g,...\\n" % row`` it wrote
before, byte for byte."""

import numpy as np
import pytest

import screwkin
from conftest import fourbar
from screwkin.analysis.position.position import PositionSolver
from screwkin.analysis.motion.sweep import sweep
from screwkin.present.numtext import W, csv_rows, g12_bytes
from screwkin.present.report import sweep_columns, sweep_csv


def texts(values):
    rows = g12_bytes(values).reshape(-1, W)
    return [r[r != 0].tobytes().decode("ascii") for r in rows]


def hard_values():
    rng = np.random.default_rng(7)
    powers = 10.0 ** rng.integers(-40, 40, 3000)
    parts = [
        rng.normal(size=3000), rng.normal(size=3000) * powers,
        np.exp(rng.uniform(-745, 709, 3000)) * rng.choice([-1.0, 1.0], 3000),
        rng.integers(-10 ** 13, 10 ** 13, 3000) / rng.choice([1.0, 2.0, 8.0, 1024.0], 3000),  # exact ties near 12 digits
        np.nextafter(powers, 0.0), np.nextafter(powers, np.inf),  # around every power of ten
        np.array([0.0, -0.0, np.inf, -np.inf, np.nan, 5e-324, -1e-310, 2.2250738585072014e-308,
                  1.7976931348623157e308, 1e12, 1e11, 999999999999.5, 999999999999.4999, 99999999999.95,
                  1e-4, 9.99999999999951e-5, 9.9999999999995e-5, 1e-5, 123456789012.5, 1234567890.125, 0.5, 2.5,
                  1.25e-5, 1e16, 1e-16, 4.440892098500626e-16, 1e100, -1e-100, 1e33, 1e-33, 9.999999999995e32]),
    ]
    return np.concatenate(parts)


def test_every_value_is_pythons_percent_g12():
    x = hard_values()
    assert texts(x) == ["%.12g" % v for v in x.tolist()]


def test_shapes_are_kept():
    x = hard_values()[:600].reshape(20, 30)
    out = g12_bytes(x)
    assert out.shape == (20, 30, W)
    assert texts(x) == ["%.12g" % v for v in x.ravel().tolist()]


@pytest.mark.parametrize("first", [0, 7, 99_995])
def test_csv_rows_are_the_row_format(first):
    rng = np.random.default_rng(first)
    cols = [rng.normal(size=40) * 10.0 ** k for k in (-6, -1, 0, 3, 14)] + [np.full(40, np.nan), np.zeros(40)]
    fmt = "%d," + ",".join(["%.12g"] * len(cols)) + "\n"
    expected = "".join(fmt % (first + k, *row) for k, row in enumerate(np.column_stack(cols).tolist()))
    assert csv_rows(cols, first) == expected
    assert csv_rows([np.zeros(0)]) == ""


def test_a_sweeps_csv_is_the_row_format(tmp_path):
    p = tmp_path / "fb.urdf"
    p.write_text(fourbar())
    mech = screwkin.load(p)
    res = sweep(PositionSolver(mech, ["crank_joint"]), "crank_joint", 0.0, 2 * np.pi, 500)
    head, cols = sweep_columns(res)
    fmt = "%d," + ",".join(["%.12g"] * len(cols)) + "\n"
    rows = "".join(fmt % (12 + k, *row) for k, row in enumerate(np.column_stack(cols).tolist()))
    assert sweep_csv(res, first_step=12, header=False) == rows


def test_long_tables_are_written_in_blocks_with_the_same_text():
    from screwkin.present import numtext

    rng = np.random.default_rng(3)
    cols = [rng.normal(size=2 * numtext.ROWS + 17) for _ in range(3)]
    fmt = "%d," + ",".join(["%.12g"] * len(cols)) + "\n"
    expected = "".join(fmt % (5 + k, *row) for k, row in enumerate(np.column_stack(cols).tolist()))
    assert csv_rows(cols, 5) == expected
