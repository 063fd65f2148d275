"""``cranefmu docs``: one page per FMU (``docs/fmus/<Name>.md``) from its built modelDescription.xml."""
from __future__ import annotations

import argparse
from pathlib import Path

from ..errors import CraneFmuError


def add_parser(sub) -> None:
    """Register ``docs`` on the subparsers ``sub`` of the cranefmu command."""
    d = sub.add_parser("docs", help="write docs/fmus/<Name>.md for every FMU from its built modelDescription.xml "
                                    "and bundled sources (builds stale FMUs first)")
    d.add_argument("--output", default=None, help="directory of the pages (default: docs/fmus in a checkout, "
                   "else ./fmu_docs)")
    d.add_argument("--check", action="store_true", help="write nothing; exit 1 if a page differs from its FMU")
    d.add_argument("only", nargs="*", help="FMU names (default: all)")


def main(args: argparse.Namespace) -> int:
    """Write the pages (0), or with --check say which differ (1 if any)."""
    from ..build import build
    from ..fmu_docs import DOCS_DIR, stale_pages, write_docs
    from ..sources import IN_CHECKOUT

    build(verbose=False, only=args.only or None)  # pages describe the FMUs as built from the sources
    # the checkout's docs/fmus; an installed package never writes into itself: ./fmu_docs instead
    output = Path(args.output) if args.output else DOCS_DIR if IN_CHECKOUT else Path("fmu_docs")
    if args.check:
        stale = stale_pages(output, args.only or None)
        for name in stale:
            print(f"{output / (name + '.md')} differs from fmus/{name}.fmu: run cranefmu docs")
        return 1 if stale else 0
    try:
        pages = write_docs(output, args.only or None)
    except OSError as err:
        raise CraneFmuError(f"cannot write the FMU pages into {output}: {err.strerror} ({err.filename}); "
                            "give --output DIR") from None
    for page in pages:
        print(f"wrote {page}")
    return 0
