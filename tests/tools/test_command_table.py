"""One pattern for every ``cranefmu`` sub-command (docs/architecture.md, "Where to change what"): a module with
``add_parser(sub)`` and ``main(args) -> int``, named in ``cli.COMMAND_MODULES``; cli.py holds the table and the
process around the command, no command of its own; only the module of the command given is imported."""
from __future__ import annotations

import argparse
import ast
import importlib
import inspect
import json
import subprocess
import sys
from pathlib import Path

import pytest

from cranefmu import cli

PACKAGE = Path(cli.__file__).parent


@pytest.mark.parametrize("name", cli.COMMANDS)
def test_every_command_module_registers_its_name_and_has_main(name):
    module = importlib.import_module(cli.COMMAND_MODULES[name])
    assert list(inspect.signature(module.main).parameters) == ["args"], name
    parser = argparse.ArgumentParser()
    sub = parser.add_subparsers(dest="command")
    module.add_parser(sub)
    assert tuple(sub.choices) == (name,)   # exactly its own sub-command, under the table's name


def _functions_and_calls(path: Path) -> tuple[set[str], list[str]]:
    tree = ast.parse(path.read_text())
    functions = {n.name for n in ast.walk(tree) if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef))}
    calls = [n.func.attr for n in ast.walk(tree) if isinstance(n, ast.Call) and isinstance(n.func, ast.Attribute)]
    return functions, calls


def test_cli_py_is_a_table_and_defines_no_command():
    functions, calls = _functions_and_calls(PACKAGE / "cli.py")
    assert [f for f in functions if f.startswith("_cmd_")] == []
    assert calls.count("add_argument") == 1   # --version only: every option is its command module's
    assert "set_defaults" not in calls


def test_no_module_dispatches_a_command_another_way():
    """No ``_cmd_*`` handler and no ``set_defaults(func=...)`` anywhere: cli.main calls the table module's main."""
    offenders = []
    for path in sorted(PACKAGE.rglob("*.py")):
        functions, _ = _functions_and_calls(path)
        text = path.read_text()
        if any(f.startswith("_cmd_") for f in functions) or "set_defaults(func=" in text:
            offenders.append(str(path.relative_to(PACKAGE)))
    assert offenders == []


def test_the_command_runs_through_its_modules_main(monkeypatch, capsys):
    scenes = importlib.import_module(cli.COMMAND_MODULES["scenes"])
    seen = []
    monkeypatch.setattr(scenes, "main", lambda args: seen.append(args.command) or 7)
    assert cli.main(["scenes"]) == 7 and seen == ["scenes"]


def test_a_command_imports_no_other_command_module():
    code = ("import json, sys; from cranefmu import cli; cli.build_parser('scenes').parse_args(['scenes']); "
            "print(json.dumps(sorted(sys.modules)))")
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert p.returncode == 0, p.stderr
    loaded = set(json.loads(p.stdout))
    others = {m for n, m in cli.COMMAND_MODULES.items() if n != "scenes"}
    assert cli.COMMAND_MODULES["scenes"] in loaded and sorted(others & loaded) == []
