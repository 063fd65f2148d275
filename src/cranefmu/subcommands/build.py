"""``cranefmu build``: the FMUs and ``.ssp`` scenes missing or older than their sources, both kinds."""
from __future__ import annotations

import argparse
import contextlib


def add_parser(sub) -> None:
    """Register ``build`` on the subparsers ``sub`` of the cranefmu command."""
    b = sub.add_parser("build", help="build the FMUs and .ssp scenes that are missing or older than their sources "
                                     "(a checkout: into fmus/ and ssp/; installed: into the user cache), the "
                                     "pythonfmu ones and, where a C compiler is found, the native ones in native/")
    b.add_argument("--force", action="store_true", help="rebuild everything")
    b.add_argument("--python-only", action="store_true", help="build the pythonfmu FMUs and scenes only, not the "
                   "native (C) ones beside them (fmus/native/, ssp/native/; built where a C compiler is found)")
    b.add_argument("--where", action="store_true", help="print the folders the FMUs and the scenes are built in "
                   "(two lines), build nothing")
    b.add_argument("--clear-cache", action="store_true", help="remove every build in the user cache (all versions; "
                   "a checkout's fmus/ and ssp/ are not touched), build nothing")
    b.add_argument("only", nargs="*", help="FMU or scene names to build (default: all)")


def main(args: argparse.Namespace) -> int:
    """Build (or, with --where / --clear-cache, say where or empty the cache); returns 0."""
    from .. import build as b
    from ..cache import clear

    if args.where:
        print(f"{b.FMU_DIR}\n{b.SSP_DIR}")
        return 0
    if args.clear_cache:
        removed = clear()
        print("\n".join(f"removed {p}" for p in removed) or "the cache holds no builds")
        return 0
    from ..fmu_kinds import build_line, build_native

    where = b.FMU_DIR.parent if b.in_cache() else f"{b.FMU_DIR} and {b.SSP_DIR}"
    done = b.build(force=args.force, only=args.only or None)
    if not args.python_only:
        with b.cache.locked(b.FMU_DIR.parent) if b.in_cache() else contextlib.nullcontext():
            done += build_native(force=args.force, only=args.only or None)
    print(f"{len(done)} file(s) built in {where}" if done else f"everything in {where} is up to date")
    print(build_line(args.only or None) if not args.python_only else
          "FMU kinds: python (pythonfmu) only, as asked (--python-only); cranefmu build without it adds the native FMUs")
    return 0
