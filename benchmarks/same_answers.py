"""Same answers before and after a restructuring (issue 42): every number a command prints in JSON.

    python benchmarks/same_answers.py record OUT.json      # run the commands below, keep their JSON
    python benchmarks/same_answers.py compare A.json B.json  # every number of A and B within 1e-12 (relative)

The commands: mobility, info, solve, screws, singularities, statics and a short sweep on every bundled
mechanism (robots/), each at the file's configuration, run in this process through screwkin.cli.main with
--json.  Keys that hold a time or a path are left out of the comparison.  Exit 1 when any number differs."""

from __future__ import annotations

import contextlib
import io
import json
import math
import re
import sys

from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
COMMANDS = (["mobility"], ["info"], ["solve"], ["screws"], ["singularities"], ["statics"])
SKIP = ("time", "seconds", "elapsed", "path", "file", "cache", "wall")


def _run(main, argv):  # noqa: ANN001, ANN202
    buf, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(buf), contextlib.redirect_stderr(err):
        try:
            code = main(argv)
        except SystemExit as e:  # argparse
            code = e.code
    return code, buf, err


def record(out: Path) -> int:
    from screwkin.cli import main

    answers: dict[str, object] = {}
    robots = sorted(p for p in (ROOT / "robots").iterdir() if p.suffix in (".urdf", ".xacro"))
    for robot in robots:
        for cmd in COMMANDS:
            argv = [*cmd, str(robot), "--json"]
            code, buf, err = _run(main, argv)
            hint = re.search(r"at the file's values: (.*?)\)?$", err.getvalue().strip())
            if code == 2 and hint:  # solve needs its inputs: those the error names, the file's values
                code, buf, err = _run(main, [*argv, *hint.group(1).split()])
            key = f"{' '.join(cmd)} {robot.name}"
            try:
                answers[key] = {"exit": code, "json": json.loads(buf.getvalue())} if code == 0 else {"exit": code}
            except ValueError:
                answers[key] = {"exit": code, "text": buf.getvalue()[:2000]}
            print(key, code, file=sys.stderr)
    out.write_text(json.dumps(answers, sort_keys=True))
    return 0


def _diff(a: object, b: object, where: str, found: list[str]) -> None:
    if any(s in where.rsplit("/", 1)[-1].lower() for s in SKIP):
        return
    if isinstance(a, dict) and isinstance(b, dict):
        for k in sorted(set(a) | set(b)):
            if k not in a or k not in b:
                found.append(f"{where}/{k}: only in {'B' if k not in a else 'A'}")
            else:
                _diff(a[k], b[k], f"{where}/{k}", found)
    elif isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            found.append(f"{where}: length {len(a)} vs {len(b)}")
        for i, (x, y) in enumerate(zip(a, b)):
            _diff(x, y, f"{where}[{i}]", found)
    elif isinstance(a, (int, float)) and isinstance(b, (int, float)) and not isinstance(a, bool):
        if not (a == b or (math.isfinite(a) and math.isfinite(b)
                           and abs(a - b) <= 1e-12 * max(1.0, abs(a), abs(b)))):
            found.append(f"{where}: {a!r} vs {b!r}")
    elif a != b:
        found.append(f"{where}: {str(a)[:80]!r} vs {str(b)[:80]!r}")


def compare(a: Path, b: Path) -> int:
    found: list[str] = []
    _diff(json.loads(a.read_text()), json.loads(b.read_text()), "", found)
    print("\n".join(found[:200]) or f"every number of {len(json.loads(a.read_text()))} answers the same (within 1e-12)")
    print(f"{len(found)} differences", file=sys.stderr)
    return 1 if found else 0


if __name__ == "__main__":
    if sys.argv[1:2] == ["record"] and len(sys.argv) == 3:
        sys.exit(record(Path(sys.argv[2])))
    if sys.argv[1:2] == ["compare"] and len(sys.argv) == 4:
        sys.exit(compare(Path(sys.argv[2]), Path(sys.argv[3])))
    sys.exit(__doc__)
