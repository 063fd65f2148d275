"""Stability map of the rope-pendulum coupling: now `cranefmu study stability-map`
(src/cranefmu/studies/stability_map.py, which documents the method); this script forwards to it.

    .venv/bin/python benchmarks/stability_map.py [--smoke|--full] [--output DIR]   # default DIR benchmarks/results
"""
from __future__ import annotations

import sys
from pathlib import Path

RESULTS = Path(__file__).resolve().parent / "results"


def main(argv: list[str] | None = None) -> int:
    from cranefmu.cli import main as cranefmu

    args = list(sys.argv[1:] if argv is None else argv)
    if "--output" not in args:
        args += ["--output", str(RESULTS)]
    return cranefmu(["study", "stability-map", *args])


if __name__ == "__main__":
    sys.exit(main())
