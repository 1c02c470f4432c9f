from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
ROBOTS = ROOT / "robots"
DATA = Path(__file__).resolve().parent / "data"
CORPUS = ROOT.parent / "shared" / "corpus" / "example-parallel-robots"


@pytest.fixture
def quiet():
    """A warn callable that collects warnings instead of printing them."""
    seen = []
    return seen.append
