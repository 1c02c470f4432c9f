"""One way to each thing (issue 37): a helper is defined once, a name has one import path, and commands
share code through the layers below them, never through each other.  An ast walk over the source, as
tests/architecture/test_layers.py does; each failure names the places to fold into one (or to rename, where the two
are different things)."""

import ast
from collections import defaultdict
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
PACKAGE = ROOT / "screwkin"
COMMANDS = PACKAGE / "commands"

#: Names more than one module defines on purpose, with the modules allowed and why.
SAME_NAME = {
    # the protocol every command module keeps (README, "How the code is laid out"; tests/architecture/test_cli_lazy.py)
    "add_parser": {f"screwkin.commands.{p.stem}" for p in COMMANDS.glob("*.py") if not p.stem.startswith("_")},
    "run": {f"screwkin.commands.{p.stem}" for p in COMMANDS.glob("*.py") if not p.stem.startswith("_")},
    # screwkin.load is the public API's (README's Python section): model.loader.load binding screwkin.Mechanism
    "load": {"screwkin", "screwkin.model.loader"},
    # the entry points of processes: the command line, and the meshcat server's own process
    "main": {"screwkin.cli", "screwkin.present.viewserver"},
    # the compiled (numba) form of model.kernel.newton's step under its name: tests/model/kernel/test_compiled.py compares the
    # two and puts one in the other's place
    "damped_step": {"screwkin.model.kernel.newton", "screwkin.model.kernel.compiled"},
}


def module_name(path: Path) -> str:
    parts = path.relative_to(ROOT).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def modules() -> dict:
    return {module_name(p): p for p in sorted(PACKAGE.rglob("*.py"))}


def defined(tree) -> set:
    """The names a module binds at its top level (functions, classes, assignments, in if/try too)."""
    out = set()
    for node in tree.body:
        for sub in ast.walk(node) if isinstance(node, (ast.If, ast.Try)) else [node]:
            if isinstance(sub, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                out.add(sub.name)
            elif isinstance(sub, (ast.Assign, ast.AnnAssign, ast.AugAssign)):
                targets = sub.targets if isinstance(sub, ast.Assign) else [sub.target]
                out |= {n.id for t in targets for n in ast.walk(t) if isinstance(n, ast.Name)}
    return out


def imported_from(path: Path, tree):
    """(screwkin module, name, line) of every ``from MODULE import NAME`` in the file."""
    here = module_name(path) if path.is_relative_to(PACKAGE) else ""
    package = here if path.name == "__init__.py" else here.rpartition(".")[0]
    for node in ast.walk(tree):
        if not isinstance(node, ast.ImportFrom):
            continue
        if node.level:
            base = package.split(".")[: len(package.split(".")) - (node.level - 1)]
            module = ".".join(base + ([node.module] if node.module else []))
        else:
            module = node.module or ""
        if module == "screwkin" or module.startswith("screwkin."):
            for alias in node.names:
                yield module, alias.name, node.lineno


def test_no_two_modules_define_the_same_helper():
    where = defaultdict(set)
    for name, path in modules().items():
        for node in ast.parse(path.read_text()).body:
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                where[node.name].add(name)
    twice = {f: sorted(m) for f, m in where.items() if len(m) > 1 and not m <= SAME_NAME.get(f, set())}
    assert not twice, ("the same function name in several modules (one implementation, or names that say how "
                       f"they differ): {twice}")


def test_the_allowed_names_are_still_there():
    """Each entry of SAME_NAME names modules that define it (an entry left over would hide a new copy)."""
    mods = modules()
    for name, allowed in SAME_NAME.items():
        for module in allowed:
            tree = ast.parse(mods[module].read_text())
            assert any(isinstance(n, ast.FunctionDef) and n.name == name for n in tree.body), (name, module)


def test_no_command_module_imports_another():
    commands = {f"screwkin.commands.{p.stem}" for p in COMMANDS.glob("*.py") if not p.stem.startswith("_")}
    found = []
    for path in sorted(COMMANDS.glob("*.py")):
        tree = ast.parse(path.read_text())
        for module, name, line in imported_from(path, tree):
            target = f"{module}.{name}" if f"{module}.{name}" in commands else module
            if target in commands and target != module_name(path):
                found.append(f"{path.relative_to(ROOT)}:{line} imports {target}")
        for node in ast.walk(tree):
            if isinstance(node, ast.Import):
                found += [f"{path.relative_to(ROOT)}:{node.lineno} imports {a.name}" for a in node.names
                          if a.name in commands and a.name != module_name(path)]
    assert not found, ("a command shares code through a module of shared pieces (commands/_*.py, present/, "
                       f"analysis/), not through another command: {sorted(set(found))}")


def test_one_import_path_for_each_name():
    """A name is imported from the module that defines it: no module re-exports another's names (the
    public API of screwkin/__init__.py apart), in the package, its tests, benchmarks and examples; and a
    module's __all__ lists only what it defines."""
    mods = modules()
    names = {m: defined(ast.parse(p.read_text())) for m, p in mods.items()}
    files = [*PACKAGE.rglob("*.py"), *(p for d in ("tests", "benchmarks", "examples") for p in (ROOT / d).rglob("*.py"))]
    found = []
    for path in sorted(files):
        for module, name, line in imported_from(path, ast.parse(path.read_text())):
            if module == "screwkin" or module not in names or f"{module}.{name}" in mods:
                continue
            if name != "*" and name not in names[module]:
                found.append(f"{path.relative_to(ROOT)}:{line}: {name} from {module}, which does not define it")
    for module, path in mods.items():
        if module == "screwkin":
            continue
        for node in ast.parse(path.read_text()).body:
            if isinstance(node, ast.Assign) and any(isinstance(t, ast.Name) and t.id == "__all__" for t in node.targets):
                found += [f"{module}.__all__ lists {e.value}, defined elsewhere" for e in node.value.elts
                          if e.value not in names[module] and f"{module}.{e.value}" not in mods]
    assert not found, found


def test_the_walks_find_what_they_look_for():
    """The checks on code written to fail them: a re-export, a command importing a command, a copy."""
    tree = ast.parse("from screwkin.present.report import table\nfrom . import draw\n")
    got = list(imported_from(COMMANDS / "solve.py", tree))
    assert ("screwkin.present.report", "table", 1) in got and ("screwkin.commands", "draw", 2) in got
    assert "table" not in defined(ast.parse((PACKAGE / "present" / "report.py").read_text()))
    assert defined(ast.parse("if x:\n    def f(): pass\nelse:\n    g = 1\nh: int = 2\n")) == {"f", "g", "h"}
