import contextlib
import urllib.request
import time
import json
import importlib.util
import os
import re
import shutil
import signal
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
ROBOTS = ROOT / "robots"
DATA = Path(__file__).resolve().parent / "data"
CORPUS = ROBOTS / "corpus" / "example-parallel-robots"  # vendored, BSD-3-Clause (its LICENSE is beside it)


def readme_fourbar() -> str:
    """The URDF of README.md's "Your first four-bar", as written there: ground O2-O4 0.10 m, crank 0.04, coupler
    0.12, rocker 0.08, every link along +x and the loop open at B (its joints' values are the crank's and the
    rocker's absolute angles)."""
    section = (ROOT / "README.md").read_text().split("## Your first four-bar", 1)[1]
    return section.split("<<'EOF'\n", 1)[1].split("\nEOF\n", 1)[0]


@pytest.fixture(autouse=True)
def _cache_of_the_session(tmp_path_factory, monkeypatch):
    """The generic solution sets (files/generic_cache.py) go to one folder of the test session, never to
    the user's cache."""
    monkeypatch.setenv("SCREWKIN_CACHE", str(tmp_path_factory.getbasetemp() / "screwkin-cache"))


@pytest.fixture
def quiet():
    """A warn callable that collects warnings instead of printing them."""
    seen = []
    return seen.append


LINK = ('<link name="{n}"><inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/>'
        '</inertial><visual><geometry><box size="0.01 0.01 0.01"/></geometry></visual></link>')
DUMMY = '<link name="{n}"/>'


def rev(name, parent, child, axis="0 0 1", xyz="0 0 0", rpy="0 0 0", jtype="revolute"):
    return (f'<joint name="{name}" type="{jtype}"><parent link="{parent}"/><child link="{child}"/>'
            f'<origin xyz="{xyz}" rpy="{rpy}"/><axis xyz="{axis}"/>'
            f'<limit lower="-3" upper="3" effort="1" velocity="1"/></joint>')


def fourbar(loop_children='<link1 link="coupler" xyz="0.12 0 0"/><link2 link="rocker" xyz="0.08 0 0"/>',
            extra=""):
    # ground pivots A=(0,0), D=(0.1,0); crank 0.04 at 90 deg; coupler 0.12 and rocker 0.08
    # placed with the angles of the closed loop (computed from the two circle intersection).
    B = np.array([0.0, 0.04])
    D = np.array([0.1, 0.0])
    d = np.linalg.norm(D - B)
    a = (0.12**2 - 0.08**2 + d**2) / (2 * d)
    h = np.sqrt(0.12**2 - a**2)
    u = (D - B) / d
    C = B + a * u + h * np.array([-u[1], u[0]])
    th_c = np.arctan2(*(C - B)[::-1])
    th_r = np.arctan2(*(C - D)[::-1])
    body = "".join(LINK.format(n=n) for n in ("ground", "crank", "coupler", "rocker"))
    body += rev("crank_joint", "ground", "crank", rpy="0 0 1.5707963267948966")
    body += rev("coupler_joint", "crank", "coupler", xyz="0.04 0 0", rpy=f"0 0 {th_c - np.pi / 2}")
    body += rev("rocker_joint", "ground", "rocker", xyz="0.1 0 0", rpy=f"0 0 {th_r}")
    body += f'<loop_joint name="C" type="revolute">{loop_children}<axis xyz="0 0 1"/></loop_joint>'
    return f'<robot name="fourbar">{body}{extra}</robot>'




def slider_crank(a=0.05, b=0.15, e=0.02, theta0=np.radians(60)):
    """Offset slider-crank: crank a about the origin, rod b, slider on the line y = e
    (prismatic along x); written closed at crank angle theta0."""
    B = a * np.array([np.cos(theta0), np.sin(theta0)])
    x0 = B[0] + np.sqrt(b**2 - (e - B[1]) ** 2)
    rod = np.arctan2(e - B[1], x0 - B[0])
    body = "".join(LINK.format(n=n) for n in ("ground", "crank", "rod", "slider"))
    body += rev("crank_joint", "ground", "crank", rpy=f"0 0 {theta0}")
    body += rev("rod_joint", "crank", "rod", xyz=f"{a} 0 0", rpy=f"0 0 {rod - theta0}")
    body += rev("slider_joint", "ground", "slider", axis="1 0 0", xyz=f"{x0} {e} 0", jtype="prismatic")
    body += (f'<loop_joint name="pin" type="revolute"><link1 link="rod" xyz="{b} 0 0"/>'
             f'<link2 link="slider" rpy="0 0 {rod}"/><axis xyz="0 0 1"/></loop_joint>')
    return f'<robot name="slider_crank">{body}</robot>'


def planar_3r(l1=0.3, l2=0.25, l3=0.1):
    body = "".join(LINK.format(n=n) for n in ("base", "l1", "l2", "l3"))
    body += rev("j1", "base", "l1") + rev("j2", "l1", "l2", xyz=f"{l1} 0 0") + rev("j3", "l2", "l3", xyz=f"{l2} 0 0")
    return f'<robot name="planar_3r">{body}</robot>'


def circles(p, r, c, s):
    """Both intersections of circle (p, r) and circle (c, s) in the plane."""
    d = np.linalg.norm(c - p)
    along = (r * r - s * s + d * d) / (2 * d)
    h = np.sqrt(r * r - along * along)
    u = (c - p) / d
    n = np.array([-u[1], u[0]])
    return [p + along * u + h * n, p + along * u - h * n]


def check_urdf(path) -> str:
    """urdfdom's check_urdf (an independent URDF parser) run on ``path``: its stdout, the run asserted
    to succeed; a skip naming it where it is not installed (under CI=true that skip fails the run)."""
    tool = shutil.which("check_urdf")
    if tool is None:
        pytest.skip("urdfdom's check_urdf is not installed")
    done = subprocess.run([tool, str(path)], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stdout + done.stderr
    return done.stdout


def screwkin_cli(*args, timeout=300):
    """``python -m screwkin ARGS`` in a process of its own: (returncode, stdout, stderr) as run."""
    return subprocess.run([sys.executable, "-m", "screwkin", *args], capture_output=True, text=True,
                          timeout=timeout)


@contextlib.contextmanager
def no_hang(seconds):
    """Fail the test (TimeoutError) if the block runs past ``seconds``: a guard against a hang or
    a blow-up (a work bound that does not hold), not a speed measurement -- speed is measured in
    benchmarks/.  Where SIGALRM is missing the block simply runs."""
    if not hasattr(signal, "setitimer"):
        yield
        return

    def fire(signum, frame):
        raise TimeoutError(f"still running after {seconds} s: a hang or an unbounded computation")

    previous = signal.signal(signal.SIGALRM, fire)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


# ---- CI must not skip what CI is meant to have (issue 23 item 7, issue 33 item 7)
#: Modules .ci/run installs (pyproject.toml's test extra) that some tests import or skip without.
CI_MODULES = ("numba", "matplotlib", "PIL", "mujoco", "viser", "pyarrow", "imageio_ffmpeg", "modern_robotics",
              "pylinkage", "example_robot_data", "hypothesis",
              "sphinx", "sphinx_gallery", "sphinxarg", "myst_parser", "pydata_sphinx_theme",  # the test extra: the docs site
              "websockets")  # (viser's own dependency: the interactive view's Chromium test drives the page with it)
#: Skip reasons that mean "something .ci/run installs is missing": under CI=true such a skip fails the run.
#: pytest.importorskip says "could not import 'M...'" (M or a submodule: 'pyarrow.parquet'), an import
#: "No module named 'M..."; the rest are the reasons the tests give for programs and data.
CI_PROVIDES = ("Chromium is not installed", "example-robot-data is not installed", "modern_robotics is not installed",
               "pylinkage is not installed", "check_urdf is not installed",
               *(f"could not import '{m}" for m in CI_MODULES), *(f"No module named '{m}" for m in CI_MODULES))
_ci_skips = []


def _skip_reason(report) -> str:
    return str(report.longrepr[-1]) if isinstance(report.longrepr, tuple) else str(report.longrepr)


def _note_ci_skip(report) -> None:
    if report.skipped and os.environ.get("CI", "").lower() in ("1", "true", "yes"):
        reason = _skip_reason(report)
        if any(what in reason for what in CI_PROVIDES):
            _ci_skips.append(f"{report.nodeid}: {reason}")


def pytest_runtest_logreport(report):
    _note_ci_skip(report)


def pytest_collectreport(report):
    """A module that skips itself at import (pytest.importorskip at its top: test_mjcf.py without
    mujoco) is skipped at collection, where pytest_runtest_logreport never sees it."""
    _note_ci_skip(report)


def pytest_sessionfinish(session, exitstatus):
    if _ci_skips:
        print(f"\n{len(_ci_skips)} test(s) skipped for something CI installs:\n  " + "\n  ".join(_ci_skips[:20]))
        session.exitstatus = 1


# ---- markers: a fast subset of about a minute is `pytest -m "not slow"` (issue 23 item 7)
#: Tests of several seconds each (measured with --durations on the 2-core machine), by node id with the file's
#: name alone (test files' names are unique in tests/, whatever folder holds them).
SLOW_TESTS = {
    "test_study.py::test_workspace_metrics_equal_screwkin_workspace",
    "test_workspace.py::test_delta_volume_against_monte_carlo_on_the_closed_form",
    "test_workspace.py::test_cli_json_png_csv",
    "test_workspace.py::test_sampling_spherical_shell_of_an_elbow_arm",
    "test_workspace.py::test_five_bar_area_is_the_annuli_intersection",
    "test_fresh_clone.py::test_tests_on_bundled_data_pass_in_the_clone",
    "test_gram_cofactors.py::test_fourbar_rocker_at_its_limit_is_stationary_and_the_cli_reports_it",
    "test_gram_cofactors.py::test_slider_crank_dead_centre_slider_cofactor_is_zero",
    "test_examples.py::test_stewart_motor_loop",
    "test_examples.py::test_readme_python_blocks_run",
    "test_examples.py::test_corpus_survey",
    "test_synthesis.py::test_four_positions_burmester_pick_and_five_positions_find_the_linkage",
    # 1.5-4 s each in the fast subset (measured 2026-11-25, 2 cores)
    "test_workspace.py::test_delta_reached_points_satisfy_the_closed_form",
    "test_nothing_silent.py::test_output_is_the_same_whatever_the_hash_seed",
    "test_points_tools.py::test_report_lists_the_points_of_its_solutions",
    "test_report.py::test_html_is_self_contained",
    "test_security.py::test_csv_quotes_names_and_neutralises_formulas",
    "test_study.py::test_a_design_past_its_timeout_is_a_failed_row",
    "test_points_tools.py::test_workspace_of_a_named_point_is_its_annulus",
    "test_points_tools.py::test_statics_of_a_load_at_a_point_is_the_load_moved_to_the_origin",
}
#: The costliest tests of the fast subset by measured CPU time (tests/slow_tests.txt: a node id a line with the
#: seconds it took, a test's name alone marking every parameter of it), run in the slow tier so that the fast
#: subset keeps about a minute while every test file keeps its cheapest tests there (issue 42 item 5).
SLOW_TESTS |= {line.split("#", 1)[0].strip() for line in (Path(__file__).parent / "slow_tests.txt").read_text().splitlines()
               if line.split("#", 1)[0].strip()}
#: Fuzz mutants beyond the first of each kind run in the slow tier (the first ones keep every operation).
FAST_MUTANTS = 20


def pytest_collection_modifyitems(config, items):
    for item in items:
        file, sep, name = item.nodeid.partition("::")
        node = file.rsplit("/", 1)[-1] + sep + name  # test_x.py::test_y[...], the folder left out
        base = node.split("[", 1)[0]
        if base in SLOW_TESTS or node in SLOW_TESTS:
            item.add_marker(pytest.mark.slow)
        if "local" in getattr(item, "fixturenames", ()) or base.endswith(("separate_scheduler_and_workers_give_the"
                                                                          "_same_table",
                                                                          "stalled_cluster_gives_failed_rows_not_a_hang")):
            item.add_marker(pytest.mark.cluster)
            item.add_marker(pytest.mark.slow)
        if any(m.name == "skipif" and "Chromium" in str(m.kwargs.get("reason", "")) for m in item.iter_markers()):
            item.add_marker(pytest.mark.chromium)
            item.add_marker(pytest.mark.slow)
        if base.startswith("test_fuzz.py::test_") and "_mutant" in base and "[" in node:
            index = node.rsplit("-", 1)[-1].rstrip("]")
            if index.isdigit() and int(index) >= FAST_MUTANTS:
                item.add_marker(pytest.mark.slow)


@pytest.fixture(scope="module")
def wide_five_bar(tmp_path_factory):
    """robots/five_bar.urdf with its motors 0.3 m apart (0.1 in the file): where the elbows are more
    than 0.3 m apart it cannot be assembled, so most of a map's grid is not reached (test_maps,
    test_pictures)."""
    text = (ROBOTS / "five_bar.urdf").read_text()
    assert text.count('<origin xyz="0.1 0 0" rpy="0 0 0"/>') == 1
    path = tmp_path_factory.mktemp("wide_five_bar") / "five_bar_wide.urdf"
    path.write_text(text.replace('<origin xyz="0.1 0 0" rpy="0 0 0"/>', '<origin xyz="0.3 0 0" rpy="0 0 0"/>'))
    return path


# ---- shared by test modules of several folders (they imported them from each other while tests/ was flat)
G, A, B, C = 0.10, 0.04, 0.12, 0.08  # ground, crank, coupler, rocker of fourbar() above


def rocker_angles(theta):
    """Both rocker angles of the four-bar for crank angle theta: the two
    intersections of the circles |X - B(theta)| = B and |X - D| = C."""
    b = A * np.array([np.cos(theta), np.sin(theta)])
    d = np.array([G, 0.0])
    dist = np.linalg.norm(d - b)
    along = (B**2 - C**2 + dist**2) / (2 * dist)
    h = np.sqrt(B**2 - along**2)
    u = (d - b) / dist
    out = []
    for sign in (1, -1):
        x = b + along * u + sign * h * np.array([-u[1], u[0]])
        out.append(np.arctan2(x[1] - d[1], x[0] - d[0]))
    return sorted(out)


def world_angles(mech, sol):
    """Crank and rocker angles from the solved placements (Pinocchio FK)."""
    import pinocchio as pin

    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, sol.q)
    R_crank = data.oMf[mech.link_frame("crank")].rotation
    R_rocker = data.oMf[mech.link_frame("rocker")].rotation
    return np.arctan2(R_crank[1, 0], R_crank[0, 0]), np.arctan2(R_rocker[1, 0], R_rocker[0, 0])


#: The planar 2R arm (0.4 m and 0.25 m to the hand) of the ellipsoids' closed form (test_ellipsoids, test_json_writer).
ARM = """<robot name="arm2r">
  <link name="base"/><link name="upper"/><link name="fore"/><link name="hand"/>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="elbow" type="revolute"><parent link="upper"/><child link="fore"/><origin xyz="0.4 0 0"/>
    <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="wrist" type="fixed"><parent link="fore"/><child link="hand"/><origin xyz="0.25 0 0"/></joint>
</robot>"""


#: robots/README.md's table of the bundled mechanisms, a row per file (test_robots, test_matrix).
ROW = re.compile(r"^\| `(?P<file>[^`]+)` \| [^|]+ \| (?P<N>-?\d+) \| (?P<J>-?\d+) \| (?P<crit>\w+) (?P<count>-?\d+) \| "
                 r"(?P<M>-?\d+) \| (?P<idle>\d+) \| (?P<eff>\d+) \| (?P<out>\S+) (?P<motion>\S+) \|")


def robots_table():
    rows = [ROW.match(line) for line in (ROBOTS / "README.md").read_text().splitlines()]
    return {m["file"]: m for m in rows if m}


def _robot_data():
    spec = importlib.util.find_spec("example_robot_data")
    if spec is None:
        for base in map(Path, sys.path):
            cand = base / "cmeel.prefix" / "share" / "example-robot-data" / "robots"
            if cand.is_dir():
                return cand
        return None
    return Path(spec.submodule_search_locations[0]).parent / "cmeel.prefix" / "share" / "example-robot-data" / "robots"


#: example-robot-data's robots folder, None when the package is not installed (test_couplings, test_published, ...).
ROBOT_DATA = _robot_data()


def _chromium_path():
    from screwkin.present.view import chromium

    return chromium()


class DevTools:
    """Headless Chromium and one page, over the DevTools protocol (the interactive view's Chromium tests and
    the docs site's): ``call`` a method, ``evaluate`` an expression, ``open`` a page and wait for it."""

    def __init__(self, profile, size=(1000, 700)):
        from websockets.sync.client import connect

        self.proc = subprocess.Popen(
            [_chromium_path(), "--headless", "--no-sandbox", "--disable-gpu", "--use-angle=swiftshader",
             "--enable-unsafe-swiftshader", "--no-first-run", "--disable-background-networking",
             "--host-resolver-rules=MAP * ~NOTFOUND, EXCLUDE 127.0.0.1", f"--user-data-dir={profile}",
             f"--window-size={size[0]},{size[1]}", "--remote-debugging-port=0",
             "--allow-file-access-from-files", "about:blank"],
            stderr=subprocess.PIPE, text=True)
        port = None
        deadline = time.monotonic() + 60
        while port is None and time.monotonic() < deadline:
            line = self.proc.stderr.readline()
            m = re.search(r"DevTools listening on ws://127\.0\.0\.1:(\d+)/", line)
            port = int(m.group(1)) if m else None
        assert port, "Chromium did not open its DevTools port"
        with urllib.request.urlopen(f"http://127.0.0.1:{port}/json/list", timeout=10) as r:
            page = next(t for t in json.load(r) if t["type"] == "page")
        self.ws = connect(page["webSocketDebuggerUrl"], max_size=None, open_timeout=20)
        self.next_id = 0

    def call(self, method, **params):
        self.next_id += 1
        self.ws.send(json.dumps({"id": self.next_id, "method": method, "params": params}))
        while True:
            msg = json.loads(self.ws.recv(timeout=60))
            if msg.get("id") == self.next_id:
                assert "error" not in msg, msg
                return msg.get("result", {})

    def evaluate(self, expression):
        return self.call("Runtime.evaluate", expression=expression, returnByValue=True)["result"].get("value")

    def open(self, url, timeout=60):
        """Navigate to ``url`` and wait until it and its pictures have loaded."""
        self.call("Page.navigate", url=url)
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if self.evaluate("document.readyState === 'complete' && location.href") == url:
                return
            time.sleep(0.2)
        raise AssertionError(f"{url} did not load")

    def close(self):
        try:
            self.ws.close()
        finally:
            self.proc.terminate()
            self.proc.wait(timeout=30)
