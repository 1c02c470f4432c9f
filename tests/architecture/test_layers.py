"""The package's imports run one way: files <- model <- analysis <- present and parallel <- cli (the public
API in screwkin/__init__.py on top), with the base modules (errors, tolerances, units) under
all of them.  An ast walk over screwkin/ finds every import, module level or not."""

import ast
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[2] / "screwkin"
LAYERS = {"errors": 0, "tolerances": 0, "units": 0, "files": 1, "model": 2, "analysis": 3, "present": 4,
          "parallel": 4, "commands": 5, "cli": 5, "__main__": 6, "__init__": 6}
# third-party imports a function may make lazily: optional, or heavy and needed by one command
# (measured cold: scipy.optimize 0.62 s, pinocchio.visualize 0.42 s, networkx 0.15 s; every command pays ~0.3 s
# in all; sympy 0.5 s, for the equations only)
# xacro (28 ms, and it replaces minidom's pretty printer when imported) only for .xacro files
# distributed (0.4-0.9 s) and pyarrow (optional: parquet tables) only for studies
# PIL (with matplotlib) and imageio_ffmpeg (optional) for draw --animate; viser and trimesh (optional) for view --interactive
# yaml (7 ms) only for sidecars and study specs; defusedxml.expatbuilder (minidom) only for .xacro files
# mujoco (optional) only for export --mjcf, to name the redundant rows of what it writes (files/mjcf_rows.py)
LAZY = {"numba", "matplotlib", "meshcat", "coal", "scipy", "pinocchio.visualize", "networkx", "sympy", "xacro",
        "distributed", "dask", "pyarrow", "PIL", "imageio_ffmpeg", "viser", "trimesh", "yaml", "defusedxml.expatbuilder",
        "mujoco"}


def module_name(path: Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def imports(path: Path):
    """(imported screwkin module, line, inside a function) for every import in the file."""
    here = module_name(path)
    package = here if path.name == "__init__.py" else here.rsplit(".", 1)[0]
    tree = ast.parse(path.read_text())
    in_function = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda)):
            in_function |= {id(n) for n in ast.walk(node) if n is not node}
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[:len(base) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            targets = [target]
            if not node.module:  # "from . import compiled"
                targets = [f"{target}.{a.name}" for a in node.names]
            for t in targets:
                yield t, node.lineno, id(node) in in_function
        elif isinstance(node, ast.Import):
            for a in node.names:
                yield a.name, node.lineno, id(node) in in_function


def layer(module: str) -> int:
    parts = module.split(".")
    return LAYERS["__init__"] if len(parts) == 1 else LAYERS[parts[1]]


def graph():
    edges = {}
    for path in PACKAGE.rglob("*.py"):
        name = module_name(path)
        edges[name] = [(t, line, lazy) for t, line, lazy in imports(path)]
    return edges


GRAPH = graph()


def test_every_module_has_a_layer():
    for name in GRAPH:
        assert name == "screwkin" or name.split(".")[1] in LAYERS, name


def test_imports_never_go_up_a_layer():
    bad = []
    for name, targets in GRAPH.items():
        for t, line, _ in targets:
            if t == "screwkin" or t.startswith("screwkin."):
                if layer(t) > layer(name):
                    bad.append(f"{name}:{line} imports {t}")
    assert not bad, "\n".join(bad)


def find_cycle(edges):
    """A cycle of the directed graph {node: targets} as a list of nodes, or None."""
    state = {}

    def visit(n, stack):
        state[n] = 1
        for m in sorted(edges.get(n, ())):
            if state.get(m) == 1:
                return stack[stack.index(m):] + [m]
            if m not in state:
                found = visit(m, stack + [m])
                if found:
                    return found
        state[n] = 2
        return None

    for n in sorted(edges):
        if n not in state:
            found = visit(n, [n])
            if found:
                return found
    return None


def test_no_import_cycle():
    edges = {n: {t for t, _, _ in ts if t in GRAPH} for n, ts in GRAPH.items()}
    assert find_cycle(edges) is None, " -> ".join(find_cycle(edges))


def rooms_of(package):
    """The import graph of screwkin/PACKAGE/ between its rooms -- each folder or module directly in it --
    as {room: {room: the first import that ties them, "module:line"}}."""
    def room(module):
        parts = module.split(".")
        return parts[2] if len(parts) > 2 and parts[1] == package else None
    edges = {}
    for name, targets in GRAPH.items():
        for t, line, _ in targets:
            a, b = room(name), room(t)
            if a and b and a != b and t in GRAPH:
                edges.setdefault(a, {}).setdefault(b, f"{name}:{line}")
    return edges


def test_the_rooms_of_analysis_and_model_import_one_way():
    """Issue 42: inside analysis/ and model/ no room imports one that imports it back, through any
    files (analysis/ had motion <-> singularities and course <-> singularities: now position/ stands
    on motion/, and both on singular.py)."""
    for package in ("analysis", "model"):
        edges = rooms_of(package)
        cycle = find_cycle({a: set(bs) for a, bs in edges.items()})
        assert cycle is None, f"{package}/: " + ", ".join(
            f"{a} -> {b} ({edges[a][b]})" for a, b in zip(cycle, cycle[1:]))


def test_the_cycle_finder_finds_cycles():
    assert find_cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == ["a", "b", "c", "a"]
    assert find_cycle({"a": {"b", "c"}, "b": {"c"}, "c": set()}) is None


def test_no_function_imports_a_screwkin_module_or_a_common_library():
    bad = []
    for name, targets in GRAPH.items():
        for t, line, lazy in targets:
            if lazy and t.split(".")[0] not in LAZY and t not in LAZY:
                bad.append(f"{name}:{line} imports {t} inside a function")
    assert not bad, "\n".join(bad)


def test_analysis_results_do_not_format_themselves():
    """Results are plain data: the text, JSON and CSV forms live in screwkin/present/."""
    bad = []
    for path in (PACKAGE / "analysis").rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ClassDef):
                for item in node.body:
                    if isinstance(item, ast.FunctionDef) and item.name in ("to_dict", "to_json", "csv", "png", "text"):
                        bad.append(f"{path.name}: {node.name}.{item.name}")
    assert not bad, bad


def test_analysis_never_prints():
    """Nothing in screwkin/analysis/ (every subfolder) prints or writes to the terminal: results are
    returned, and long work reports its progress through a callable the caller gives
    (present/progress.Progress draws it).  A call of print, or any use of sys.stdout/sys.stderr."""
    bad = []
    for path in (PACKAGE / "analysis").rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id == "print":
                bad.append(f"{path.relative_to(PACKAGE)}:{node.lineno} print()")
            if (isinstance(node, ast.Attribute) and node.attr in ("stdout", "stderr")
                    and isinstance(node.value, ast.Name) and node.value.id == "sys"):
                bad.append(f"{path.relative_to(PACKAGE)}:{node.lineno} sys.{node.attr}")
    assert not bad, bad


def test_the_walks_reach_every_subfolder():
    """The checks above walk analysis/'s subfolders (rglob): a glob of the top folder alone saw 3 of its
    modules.  Every module of analysis/ is in the import graph too."""
    modules = sorted(p for p in (PACKAGE / "analysis").rglob("*.py") if p.name != "__init__.py")
    assert len(modules) > len(list((PACKAGE / "analysis").glob("*.py"))) + 20
    assert all(module_name(p) in GRAPH for p in modules)


