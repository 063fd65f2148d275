"""README.md stays a short front page whose commands work, whose links stay inside the repository and whose
scene table is the one `python -m cranefmu.scenes.docs` generates."""
from __future__ import annotations

import re
import shlex
import tomllib
from pathlib import Path

import pytest

from cranefmu.cli import build_parser

ROOT = Path(__file__).resolve().parents[2]
README = ROOT / "README.md"
TEXT = README.read_text()


def _commands() -> list[list[str]]:
    """Every `cranefmu ...` command in the README's indented code lines, as argv after `cranefmu`."""
    out = []
    for line in TEXT.splitlines():
        if not line.startswith("    ") or "cranefmu " not in line:
            continue
        for part in line.split("#")[0].split("&&"):
            words = shlex.split(part)
            if words and words[0].endswith("/cranefmu"):
                out.append(words[1:])
    return out


def test_at_most_200_lines():
    assert len(TEXT.splitlines()) <= 200, f"README.md has {len(TEXT.splitlines())} lines: at most 200"


def test_quick_start_commands_are_the_two_install_lines():
    quick = TEXT.split("## Quick start", 1)[1].split("\n## ", 1)[0]
    lines = [line.strip() for line in quick.splitlines() if line.startswith("    ")]
    assert lines == [
        "python3 -m venv .venv && .venv/bin/pip install . && .venv/bin/cranefmu run elastic_pendulum "
        "--stop-time 20 --output out.csv",
        "python3 -m venv .venv && .venv/bin/pip install -e '.[test]' && .venv/bin/python -m pytest -q"]
    # .ci/run runs the README's test command (its own venv)
    ci = (ROOT / ".ci" / "run").read_text()
    assert re.search(r'^"\$venv/bin/python" -m pytest -q( --durations=\d+)?$', ci, re.M)
    extras = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["optional-dependencies"]
    assert "test" in extras and "pytest" in " ".join(extras["test"])


@pytest.mark.parametrize("argv", _commands(), ids=lambda a: " ".join(a[:2]))
def test_every_command_parses(argv):
    """Each command names a sub-command and options `cranefmu` has (argparse exits on an unknown one)."""
    try:
        build_parser().parse_args(argv)
    except SystemExit as exit:
        pytest.fail(f"README command `cranefmu {' '.join(argv)}` does not parse (exit {exit.code})")


def test_commands_found():
    assert {a[0] for a in _commands()} >= {"run", "info", "sweep", "check", "compose", "study"}


def test_links_stay_in_the_repository_and_exist():
    """The seeds were cited by a path in the project workspace (`../shared/seeds/README.md`), outside the
    repository; every relative link must name a file or folder of the checkout."""
    assert "../" not in TEXT and "/work/" not in TEXT
    for target in re.findall(r"\]\(([^)#]+)(?:#[^)]*)?\)", TEXT):
        if target.startswith(("http://", "https://")):
            continue
        assert (ROOT / target).exists(), f"README.md links to {target}, which is not in the repository"


def test_no_result_quoted_from_a_commit():
    """README quoted a run's numbers 'at commit 6f15580': results come from generated files instead."""
    assert not re.search(r"at commit [0-9a-f]{7}", TEXT)


def test_scene_table_is_the_generated_one(built):
    from cranefmu.scenes import docs as scene_docs

    assert scene_docs.readme_text(TEXT) == TEXT, \
        "README.md's scene table is out of date: run `python -m cranefmu.scenes.docs` and commit README.md"


def test_architecture_map_names_files_that_exist():
    """docs/architecture.md's 'Where to change what': every repository path it names is there (a newcomer
    follows them), and it has a row for a rope model, an algorithm, a scene and a CLI command."""
    page = (ROOT / "docs" / "architecture.md").read_text()
    table = page.split("## Where to change what", 1)[1].split("\n## ", 1)[0]
    rows = [line.split("|")[1].strip() for line in table.splitlines() if line.startswith("| ") and "---" not in line]
    assert {"a rope model (or any subsystem's equations)", "a coupling algorithm", "a scene", "a CLI command"} <= set(rows)
    paths = {p for p in re.findall(r"`([\w./-]+/[\w.-]+\.(?:py|c|md|toml))`", table)}
    assert len(paths) >= 10
    for path in paths:   # from the root, the package (master/algorithms.py) or docs/
        assert any((base / path).exists() for base in (ROOT, ROOT / "src" / "cranefmu", ROOT / "docs")), \
            f"docs/architecture.md names {path}, which is not in the repository"
