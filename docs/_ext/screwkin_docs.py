"""The command reference, generated from screwkin's own parser (so that it cannot drift from it).

``screwkin.cli`` builds its parser lazily: ``_parser(argv)`` builds in full only the command that
``argv`` invokes.  ``parser_NAME()`` (``parser_mobility``, ...) is that command's subparser, built as
``screwkin NAME --help`` builds it, for sphinx-argparse's ``:func:``.  At ``builder-inited`` the
extension writes ``reference/commands/NAME.md`` for every command of ``screwkin.cli.COMMANDS`` (a page
per command: its help line, the hand-written notes of ``reference/notes/NAME.md`` where there are
some, and the options from the parser) and their index; those pages are build products (ignored by
git), rewritten only when their text changes.
"""

from __future__ import annotations

from pathlib import Path

HERE = Path(__file__).resolve().parents[1]  # docs/


def commands():
    """(name, help line) of every command, in the order `screwkin` lists them."""
    from screwkin.cli import COMMANDS

    return COMMANDS


def parser(name: str):
    """The subparser of ``screwkin NAME``, as ``screwkin NAME --help`` builds it."""
    import argparse

    from screwkin.cli import _parser

    top = _parser([name])
    sub = next(a for a in top._actions if isinstance(a, argparse._SubParsersAction))
    command = sub.choices[name]
    for action in command._actions:  # the help is plain text; sphinx-argparse reads it as reStructuredText
        if action.help and action.help is not argparse.SUPPRESS:
            action.help = _plain(action.help)
    return command


def _plain(text: str) -> str:
    """``text`` with reStructuredText's inline markup characters escaped (``N*m``, ``**``, backquotes)."""
    return text.replace("\\", "\\\\").replace("*", "\\*").replace("`", "\\`").replace("|", "\\|")


def __getattr__(attr):  # parser_NAME, for sphinx-argparse's :func:
    if attr.startswith("parser_"):
        name = attr[len("parser_"):]
        return lambda: parser(name)
    raise AttributeError(attr)


def page(name: str, help: str) -> str:
    notes = HERE / "reference" / "notes" / f"{name}.md"
    lines = [f"# screwkin {name}", "", f"{help[0].upper()}{help[1:]}.", ""]
    if notes.is_file():
        lines += [f"```{{include}} ../notes/{name}.md", "```", ""]
    lines += ["## Options", "",
              f"Generated from the parser: `screwkin {name} --help` prints the same.", "",
              "```{eval-rst}",
              ".. argparse::",
              "   :module: screwkin_docs",
              f"   :func: parser_{name}",
              f"   :prog: screwkin {name}",
              "```", ""]
    return "\n".join(lines)


def index() -> str:
    lines = ["# Commands", "",
             "One page per command, generated from the argument parser of `screwkin.cli` (the options, their "
             "defaults and help are the parser's own).  Every command that reads a FILE also takes the "
             "[options every command shares](../options.md).", "",
             "| command | what it does |", "|---|---|"]
    lines += [f"| [`{name}`]({name}.md) | {help} |" for name, help in commands()]
    lines += ["", "```{toctree}", ":hidden:", "", *[name for name, _ in commands()], "```", ""]
    return "\n".join(lines)


def api() -> str:
    """The API page: every public name of screwkin/__init__.py (its ``__all__``), with its docstring."""
    import inspect

    import screwkin

    lines = ["# Python API", "",
             "Generated from the docstrings of the public names of `screwkin/__init__.py` (its `__all__`), in "
             "its order; [Python](python.md) shows them at work.  Every other module is internal: its names "
             "may move.", "", "```{eval-rst}", ".. currentmodule:: screwkin", ""]
    for name in screwkin.__all__:
        obj = getattr(screwkin, name)
        if inspect.isclass(obj):
            lines += [f".. autoclass:: {name}", "   :members:" if name in API_MEMBERS else "", ""]
        else:
            lines += [f".. autofunction:: {name}", ""]
    lines += ["```", ""]
    return "\n".join(lines)


#: Classes whose methods are documented with them (the others: their docstring, fields in it).
API_MEMBERS = {"Mechanism", "PositionSolver", "SerialJacobians"}


def write_pages(app=None) -> list[Path]:
    """Write reference/commands/*.md and reference/api.md (only those whose text changed); return their
    paths."""
    out = HERE / "reference" / "commands"
    out.mkdir(parents=True, exist_ok=True)
    written = []
    api_page = HERE / "reference" / "api.md"
    if not api_page.is_file() or api_page.read_text() != api():
        api_page.write_text(api())
    wanted = {"index.md": index(), **{f"{name}.md": page(name, help) for name, help in commands()}}
    for file, text in wanted.items():
        path = out / file
        if not path.is_file() or path.read_text() != text:
            path.write_text(text)
        written.append(path)
    for stale in out.glob("*.md"):
        if stale.name not in wanted:
            stale.unlink()
    return written


def plain_docstrings(app, what, name, obj, options, lines):
    """A docstring that is not valid reStructuredText (screwkin's are plain text with indented lists and
    ``|x|`` for norms) is shown as it is written, a literal block, rather than mis-rendered with warnings."""
    import docutils.core
    import docutils.nodes

    text = "\n".join(lines)
    if not text.strip():
        return
    tree = docutils.core.publish_doctree(text, settings_overrides={"report_level": 5, "halt_level": 5,
                                                                     "warning_stream": False, "env": app.env})
    if any(m["level"] >= 2 for m in tree.findall(docutils.nodes.system_message)):
        lines[:] = ["::", "", *("    " + line for line in text.split("\n")), ""]


def setup(app):
    app.connect("builder-inited", write_pages)
    app.connect("autodoc-process-docstring", plain_docstrings)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
