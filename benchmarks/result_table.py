"""Stamp and save of the tables the physics benchmarks write to benchmarks/results/ (commit, date, load)."""
from __future__ import annotations

import os
import subprocess
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def stamp(script: str) -> str:
    """'Commit abc1234, 2026-11-26 02:26 UTC, load 1.0 (benchmarks/<script>)' for a table's header."""
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True,
                            text=True).stdout.strip()
    return (f"Commit {commit}, {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, load "
            f"{os.getloadavg()[0]:.1f} (benchmarks/{script})")


def save(name: str, lines: list[str], t0: float | None = None) -> None:
    """Print the table ``lines`` (with the run time since ``t0``) and write benchmarks/results/<name>.md."""
    if t0 is not None:
        lines = [*lines, "", f"Run time {time.time() - t0:.0f} s."]
    text = "\n".join(lines) + "\n"
    print(text)
    (ROOT / "benchmarks" / "results" / f"{name}.md").write_text(text)


def write(path: str | Path, lines: list[str]) -> int:
    """Print the table ``lines``, write them to ``path`` and say so; 0, a script's exit status."""
    text = "\n".join(lines)
    print(text)
    Path(path).write_text(text + "\n")
    print(f"written {path}")
    return 0
