"""The ``cranefmu`` sub-commands that have no package of their own, one module each with ``add_parser(sub)``
(registers the sub-command and its options on the subparsers ``sub``) and ``main(args) -> int`` (runs it on
the parsed arguments; returns the exit code).  A command whose work lives in a package has the same two
functions in that package's ``command.py`` (``sweep/``, ``compose/``, ...); :data:`cranefmu.cli.COMMANDS`
names the module of each.  (Not the operator commands of a run: :mod:`cranefmu.master.commands`.)

Internal: no module here is public API (its face: the ``cranefmu`` commands; docs/architecture.md)."""
