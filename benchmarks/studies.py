"""The published studies now live in the package: `cranefmu study NAME` (src/cranefmu/studies/).
This script forwards to it, writing into docs/studies/ as before.

    .venv/bin/python benchmarks/studies.py load-chart [--full|--smoke]   # = cranefmu study load-chart --output docs/studies
    .venv/bin/python benchmarks/studies.py stability                     # = cranefmu study stability-map ...
    .venv/bin/python benchmarks/studies.py all --smoke --output /tmp/s   # every study at smoke size
"""
from __future__ import annotations

import sys
from pathlib import Path

DOCS = Path(__file__).resolve().parent.parent / "docs" / "studies"
ALIASES = {"stability": "stability-map"}


def main(argv: list[str] | None = None) -> int:
    from cranefmu.cli import main as cranefmu

    args = list(sys.argv[1:] if argv is None else argv)
    if args and args[0] in ALIASES:
        args[0] = ALIASES[args[0]]
    if "--output" not in args:
        args += ["--output", str(DOCS)]
    return cranefmu(["study", *args])


if __name__ == "__main__":
    sys.exit(main())
