"""Commands of the command line kept in modules of their own, one per command: each module
has ``NAME``, ``NEEDS_MECHANISM`` (whether FILE is a mechanism the CLI loads first),
``add_parser(sub, common, scaled)`` (its subparser; ``common(sp)`` adds the options every
command takes, ``scaled(sp)`` --length and --point) and ``run(mech, args) -> int``.
They sit with cli.py, above every other layer, and print what present/ formats."""
