"""``cranefmu build-fmi3``: FMI 3.0 variants ``fmus/<Name>3.fmu`` (pythonfmu3, same physics and adapter)."""
from __future__ import annotations

import argparse

from ..errors import CraneFmuError


def add_parser(sub) -> None:
    """Register ``build-fmi3`` on the subparsers ``sub`` of the cranefmu command."""
    f3 = sub.add_parser("build-fmi3", help="build FMI 3.0 variants fmus/<Name>3.fmu (pythonfmu3, same physics "
                                           "and adapter as the FMI 2.0 FMUs)")
    f3.add_argument("only", nargs="*", help="FMU names (default: all)")


def main(args: argparse.Namespace) -> int:
    """Build the named FMI 3.0 FMUs (default all); returns 0."""
    from ..build import build, fmu_scripts

    from ..build import build_fmi3

    try:
        import pythonfmu3.builder  # noqa: F401  (build_fmi3's builder, imported when it builds)
    except ImportError as err:
        if not (err.name or "").startswith("pythonfmu3"):
            raise
        raise CraneFmuError("build-fmi3 needs pythonfmu3, which is not installed: pip install 'cranefmu[fmi3]'") from None

    names = args.only or [s.stem for s in fmu_scripts()]
    known = {s.stem for s in fmu_scripts()}
    unknown = [n for n in names if n not in known]
    if unknown:
        raise CraneFmuError(f"FMU {unknown[0]!r} is unknown: one of {', '.join(sorted(known))}")
    build(verbose=False, only=names)
    for name in names:
        print(f"built {build_fmi3(name)}")
    return 0
