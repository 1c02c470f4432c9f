"""Planar motions side by side in one process: screwkin's sweep against pylinkage, mechanism,
rational_linkages and a numpy closed form (the floor).

    pip install -e '.[bench]'
    python benchmarks/planar.py [--repeat 5] [--quick]

Each contestant runs ``repeat`` times (after one warm-up call: imports, numba compilation), the
peers of one motion in alternation, round after round; the table gives the median and the best.  The machines are shared and noisy:
read the ratios, measured in the same run.  Motions:

- pylinkage 1.3's four-bar (crank 1, coupler 3, rocker 3, ground 4), 10,000 crank angles:
  pylinkage ``fourbar(...).step(iterations=N)`` (positions only); screwkin.sweep on
  robots/fourbar.urdf.xacro with those lengths (positions, rates and accelerations of every
  joint), the closed form and the tracker; the same numbers in numpy, vectorized (positions,
  omega and alpha of the coupler and rocker): the floor;
- pylinkage's Strider (docs/examples/strider.py, built with its components) and
  robots/strider.urdf, 360 steps of a crank turn;
- ``mechanism``'s four-bar (its readme: vector loop solved by fsolve, ``iterate``), 500 angles;
- rational_linkages' Bennett (``models.bennett_ark24().direct_kinematics``, one pose per joint
  angle) and screwkin.sweep on robots/bennett.urdf (the tracker: a spatial loop), 100 angles;
- end to end from the shell: ``screwkin sweep ... --steps 10000 --json`` against a Python
  script that imports pylinkage and steps its four-bar 10,000 times.
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

N4 = 10_000
FOURBAR = {"crank": "1", "coupler": "3", "rocker": "3", "ground": "4"}


def timed(fn):
    t = time.perf_counter()
    fn()
    return time.perf_counter() - t


def closed_form_fourbar(n=N4, a=1.0, b=3.0, c=3.0, d=4.0, omega=1.0):
    """Positions, omega and alpha of the coupler and rocker of the four-bar, every crank angle at once."""
    th = np.linspace(0.0, 2 * np.pi, n + 1)
    A = a * np.stack([np.cos(th), np.sin(th)])
    w = np.array([[d], [0.0]]) - A
    dd = np.hypot(*w)
    along = (dd ** 2 + b ** 2 - c ** 2) / (2 * dd)
    h = np.sqrt(b ** 2 - along ** 2)
    B = A + (along * w + h * np.stack([-w[1], w[0]])) / dd
    t3 = np.arctan2(B[1] - A[1], B[0] - A[0])
    t4 = np.arctan2(B[1], B[0] - d)
    # velocity loop: a w2 e2 + b w3 e3 = c w4 e4 (e = i exp(i th)); Cramer's rule
    s = np.sin(t4 - t3)
    w3 = a * omega * np.sin(th - t4) / (b * s)
    w4 = a * omega * np.sin(th - t3) / (c * s)
    al3 = (a * omega ** 2 * np.cos(th - t4) + b * w3 ** 2 * np.cos(t3 - t4) - c * w4 ** 2) / (b * s)
    al4 = (a * omega ** 2 * np.cos(th - t3) + b * w3 ** 2 - c * w4 ** 2 * np.cos(t4 - t3)) / (c * s)
    return B, t3, t4, w3, w4, al3, al4


def pylinkage_strider(n=360):
    from pylinkage.actuators import Crank
    from pylinkage.components import Ground
    from pylinkage.dyads import FixedDyad, RRRDyad
    from pylinkage.simulation import Linkage

    A, Y = Ground(0, 0, name="A"), Ground(0, 1, name="Y")
    B = FixedDyad(anchor1=A, anchor2=Y, distance=2, angle=-np.pi / 4, name="B")
    Bp = FixedDyad(anchor1=A, anchor2=Y, distance=2, angle=np.pi / 4, name="Bp")
    C = Crank(anchor=A, radius=1, angular_velocity=-2 * np.pi / n, name="C")
    D = RRRDyad(anchor1=Bp, anchor2=C.output, distance1=1.8, distance2=2.6, name="D")
    E = RRRDyad(anchor1=B, anchor2=C.output, distance1=1.8, distance2=2.6, name="E")
    F = FixedDyad(anchor1=C.output, anchor2=E, distance=1.4, angle=-(np.pi + 0.2), name="F")
    G = FixedDyad(anchor1=C.output, anchor2=D, distance=1.4, angle=np.pi + 0.2, name="G")
    H = RRRDyad(anchor1=D, anchor2=F, distance1=2.5, distance2=1.8, name="H")
    I_ = RRRDyad(anchor1=E, anchor2=G, distance1=2.5, distance2=1.8, name="I")
    s = Linkage([A, Y, B, Bp, C, D, E, F, G, H, I_], name="Strider")
    s.set_coords([(0, 0), (0, 1), (1.41, 1.41), (-1.41, 1.41), (0, -1), (-2.25, 0), (2.25, 0), (-1.4, -1.2),
                  (1.4, -1.2), (-2.7, -2.7), (2.7, -2.7)])
    return list(s.step(iterations=n))


def mechanism_fourbar(n):
    import mechanism as mc

    O, A, B, C = mc.get_joints("O A B C")
    a = mc.Vector((O, A), r=1)
    b = mc.Vector((A, B), r=3)
    c = mc.Vector((O, C), r=4, theta=0, style="ground")
    d = mc.Vector((C, B), r=3)
    th = np.linspace(0, 2 * np.pi, n)

    def loop(x, i):
        return a(i) + b(x[0]) - c() - d(x[1])

    m = mc.Mechanism(vectors=(a, b, c, d), origin=O, loops=loop, pos=th, vel=np.ones(n), acc=np.zeros(n),
                     guess=(np.deg2rad([60, 100]), np.array([1.0, 1.0]), np.array([1.0, 1.0])))
    m.iterate()
    return m


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--quick", action="store_true", help="skip the tracker, mechanism and rational_linkages")
    args = ap.parse_args(argv)

    import screwkin
    from screwkin.analysis.position.position import PositionSolver
    from screwkin.analysis.motion.sweep import sweep

    fb = screwkin.load(ROOT / "robots" / "fourbar.urdf.xacro", args=FOURBAR)
    fb_solver = PositionSolver(fb)
    st = screwkin.load(ROOT / "robots" / "strider.urdf")
    st_solver = PositionSolver(st)
    from pylinkage.mechanism import fourbar

    rows = {}  # label -> (times, note)

    def contest(label, fn, repeat=args.repeat, note=""):
        fn()  # warm-up
        rows[label] = ([timed(fn) for _ in range(repeat)], note)

    def rounds(*entries, repeat=args.repeat):
        """(label, fn, note) entries measured in alternation, ``repeat`` rounds (after a warm-up each)."""
        for label, fn, note in entries:
            fn()
            rows[label] = ([], note)
        for _ in range(repeat):
            for label, fn, _ in entries:
                rows[label][0].append(timed(fn))

    rounds(("four-bar: numpy closed form (floor)", lambda: closed_form_fourbar(), "positions, omega, alpha"),
           ("four-bar: pylinkage fourbar().step", lambda: list(fourbar(
               crank=1.0, coupler=3.0, rocker=3.0, ground=4.0, omega=2 * np.pi / N4).step(iterations=N4)),
            "positions"),
           ("four-bar: screwkin.sweep (API)", lambda: sweep(fb_solver, "crank_joint", 0.0, 2 * np.pi, N4),
            "q, rates, accelerations"))
    if not args.quick:
        contest("four-bar: screwkin.sweep, tracker (closed_form=False)",
                lambda: sweep(fb_solver, "crank_joint", 0.0, 2 * np.pi, N4, closed_form=False), repeat=1,
                note="q, rates, accelerations")
    rounds(("Strider: pylinkage Linkage.step", lambda: pylinkage_strider(), "positions"),
           ("Strider: screwkin.sweep (API)", lambda: sweep(st_solver, "crank_joint", 0.0, -2 * np.pi, 360),
            "q, rates, accelerations"))

    def fresh_sweep():  # a mechanism loaded anew each time: the first sweep pays every set-up (issue 38)
        return sweep(PositionSolver(screwkin.load(ROOT / "robots" / "strider.urdf")), "crank_joint", 0.0, -2 * np.pi,
                     360)

    def fresh_only():
        m = screwkin.load(ROOT / "robots" / "strider.urdf")
        t = time.perf_counter()
        sweep(PositionSolver(m), "crank_joint", 0.0, -2 * np.pi, 360)
        return time.perf_counter() - t

    rounds(("Strider, fresh: pylinkage builds it and steps it", lambda: pylinkage_strider(), "positions"),
           ("Strider, fresh: screwkin.load + first sweep", fresh_sweep, "q, rates, accelerations"))
    rows["Strider, fresh: screwkin's first sweep alone (load not counted)"] = (
        [fresh_only() for _ in range(args.repeat)], "q, rates, accelerations")
    contest("Strider: screwkin, its start solve(starts=8) alone", lambda: st_solver.solve({"crank_joint": 0.0},
                                                                                            starts=8))
    if not args.quick:
        try:
            contest("four-bar, 500 angles: mechanism (fsolve)", lambda: mechanism_fourbar(500), repeat=1,
                    note="positions, velocities, accelerations")
            contest("four-bar, 500 angles: screwkin.sweep (API)",
                    lambda: sweep(fb_solver, "crank_joint", 0.0, 2 * np.pi, 499), note="same")
        except ImportError as exc:
            print(f"mechanism not measured: {exc}")
        try:
            from rational_linkages import models

            ben = models.bennett_ark24()
            angles = np.linspace(0.0, 2.0, 100)
            contest("Bennett, 100 angles: rational_linkages direct_kinematics",
                    lambda: [ben.direct_kinematics(a) for a in angles], repeat=3, note="tool pose")
            bm = screwkin.load(ROOT / "robots" / "bennett.urdf")
            bs = PositionSolver(bm)
            contest("Bennett, 100 angles: screwkin.sweep (tracker)",
                    lambda: sweep(bs, bm.actuated[0], 0.0, 2.0, 99), repeat=3, note="q, rates, accelerations")
        except ImportError as exc:
            print(f"rational_linkages not measured: {exc}")

    # end to end from the shell
    env_py = sys.executable
    cli = [env_py, "-m", "screwkin", "sweep", str(ROOT / "robots" / "fourbar.urdf.xacro"),
           *[f"--arg={k}={v}" for k, v in FOURBAR.items()], "--input", "crank_joint", "--from", "0",
           "--to", "360deg", "--steps", str(N4), "--json"]
    script = ("import numpy as np, json\nfrom pylinkage.mechanism import fourbar\n"
              f"steps = list(fourbar(crank=1.0, coupler=3.0, rocker=3.0, ground=4.0, omega=2*np.pi/{N4})"
              f".step(iterations={N4}))\nprint(json.dumps(steps))\n")
    py = [env_py, "-c", script]

    def shell(cmd):
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, cwd=ROOT,
                       env={"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin"})

    rounds(("shell: python script importing pylinkage, 10,000 steps, JSON", lambda: shell(py), "positions"),
           ("shell: screwkin sweep --steps 10000 --json", lambda: shell(cli),
            "q, rates, accelerations, link and point motion, transmission angles"))
    contest("shell: python -c 'import screwkin.cli' (start-up)", lambda: shell([env_py, "-c", "import screwkin.cli"]))

    print("| motion and tool | computes | median [ms] | best [ms] |")
    print("|---|---|---|---|")
    for label, (ts, note) in rows.items():
        print(f"| {label} | {note} | {statistics.median(ts) * 1e3:.1f} | {min(ts) * 1e3:.1f} |")
    med = {k: statistics.median(v[0]) for k, v in rows.items()}

    def ratio(a, b):
        return f"{med[a] / med[b]:.2f}" if a in med and b in med else "-"

    print()
    print("| ratio (medians) | value |")
    print("|---|---|")
    print(f"| four-bar API: screwkin / pylinkage | {ratio('four-bar: screwkin.sweep (API)', 'four-bar: pylinkage fourbar().step')} |")
    print(f"| four-bar API: screwkin / numpy floor | {ratio('four-bar: screwkin.sweep (API)', 'four-bar: numpy closed form (floor)')} |")
    print(f"| Strider API: screwkin / pylinkage | {ratio('Strider: screwkin.sweep (API)', 'Strider: pylinkage Linkage.step')} |")
    print(f"| Strider, fresh mechanism (load + first sweep): screwkin / pylinkage | "
          f"{ratio('Strider, fresh: screwkin.load + first sweep', 'Strider, fresh: pylinkage builds it and steps it')} |")
    alone = "Strider, fresh: screwkin's first sweep alone (load not counted)"
    print(f"| Strider, fresh mechanism (first sweep alone): screwkin / pylinkage | "
          f"{ratio(alone, 'Strider, fresh: pylinkage builds it and steps it')} |")
    print(f"| four-bar shell: screwkin / pylinkage script | {ratio('shell: screwkin sweep --steps 10000 --json', 'shell: python script importing pylinkage, 10,000 steps, JSON')} |")
    print(f"| four-bar, 500 angles: mechanism / screwkin | {ratio('four-bar, 500 angles: mechanism (fsolve)', 'four-bar, 500 angles: screwkin.sweep (API)')} |")
    print(f"| Bennett: rational_linkages / screwkin | {ratio('Bennett, 100 angles: rational_linkages direct_kinematics', 'Bennett, 100 angles: screwkin.sweep (tracker)')} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
