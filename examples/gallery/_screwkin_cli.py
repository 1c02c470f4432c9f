"""The helper the gallery's scripts share: run ``screwkin ARGS --json`` and return its answer."""

import json
import subprocess
import sys
from pathlib import Path

ROBOTS = Path(__file__).resolve().parents[2] / "robots"


def screwkin(*args):
    """``screwkin ARGS --json``'s object (the command line as a user types it; exit 0 checked)."""
    p = subprocess.run([sys.executable, "-m", "screwkin", *map(str, args), "--json"], capture_output=True,
                       text=True, check=False)
    if p.returncode != 0:
        raise RuntimeError(p.stderr)
    return json.loads(p.stdout)
