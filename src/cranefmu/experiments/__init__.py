"""Experiments: TOML files of a scene, parameter changes, operator commands and assertions
(``cranefmu check``, ``cranefmu run FILE.toml``; docs/experiments.md).

:mod:`.reader` (the file format), :mod:`.scene_check` (against the scene), :mod:`.profiles` (command
profiles, input shapers), :mod:`.expressions` (the safe evaluator), :mod:`.assertions`, :mod:`.runner`,
:mod:`.crane_commands` (the boom's telescope / luff / slew commands bound to its command inputs),
:mod:`.command` (the command line).

Internal: no module here is public API (its face: ``cranefmu check``, ``cranefmu run FILE.toml``; docs/architecture.md).
"""
