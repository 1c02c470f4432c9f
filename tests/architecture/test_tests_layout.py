"""The tests mirror the package (issue 42 item 5): a newcomer changing screwkin/model/state.py finds its tests
in tests/model/, those of a command's whole behaviour in tests/commands/, and the checks on the code's shape
(layers, module map, one place, literals, tiers) in tests/architecture/.  Counted from the file tree."""

from pathlib import Path

TESTS = Path(__file__).resolve().parents[1]
PACKAGE = TESTS.parent / "screwkin"
#: Folders of tests/ that are not a room of the package: the checks on the package's shape as a whole.
NOT_ROOMS = {"architecture"}


def _modules():
    return sorted(TESTS.rglob("test_*.py"))


def _room(path: Path) -> str:
    return path.parent.relative_to(TESTS).as_posix()


def test_most_test_modules_sit_in_the_folder_of_what_they_test():
    """At least 70% of the test modules are in a folder of tests/ whose path is a folder of screwkin/
    (tests/analysis/forces/ for screwkin/analysis/forces/); the others are the architecture checks and a
    few of the package's top-level modules (units.py, examples/)."""
    modules = _modules()
    mirrored = [p for p in modules if _room(p) != "." and (PACKAGE / _room(p)).is_dir()]
    assert len(modules) > 90
    assert len(mirrored) >= 0.7 * len(modules), (len(mirrored), len(modules))


def test_every_folder_of_tests_is_a_room_of_the_package_or_the_architecture_checks():
    """A folder of tests/ that holds test modules names a folder of screwkin/ (or one the issue's layout
    creates beside the present ones: model/kernel, model/homotopy, analysis/position), so the tree stays a
    map of the package."""
    planned = {"model/kernel", "model/homotopy", "analysis/position"}
    stray = {_room(p) for p in _modules()} - {"."} - NOT_ROOMS - planned
    assert not {room for room in stray if not (PACKAGE / room).is_dir()}, stray


def test_test_module_names_are_unique():
    """pytest imports test modules by their file name (rootdir conftest, no __init__.py: the default
    'prepend' import mode), and conftest.SLOW_TESTS names tests by file name and test: two files of one
    name in two folders would clash."""
    names = [p.name for p in _modules()]
    assert len(names) == len(set(names)), sorted(n for n in names if names.count(n) > 1)


def test_no_test_module_is_named_after_a_round():
    """Tests are named after the module or the behaviour they check, not the round or issue that added
    them (test_hostile_round3.py was folded into test_hostile_files.py)."""
    assert not [p.name for p in _modules() if "_round" in p.stem or "_issue" in p.stem]
