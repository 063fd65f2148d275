"""``cranefmu scenes``: the shipped scenes, each with the question it answers (from :mod:`cranefmu.scenes`)."""
from __future__ import annotations

import argparse


def lines() -> list[str]:
    """One line per shipped scene: its name, then its question."""
    from ..scenes.catalog import scene_names
    from ..scenes import SCENES

    names = scene_names()
    width = max((len(n) for n in names), default=0)
    out = [f"{name:<{width}}  {SCENES[name].question if name in SCENES else '(no description)'}" for name in names]
    return out or ["this cranefmu carries no scene sources: give cranefmu run a path to an .ssp file"]


def add_parser(sub) -> None:
    """Register ``scenes`` on the subparsers ``sub`` of the cranefmu command."""
    sub.add_parser("scenes", help="list the shipped scenes with the question each answers "
                                  "(cranefmu info SCENE for one in detail)")


def main(args: argparse.Namespace) -> int:
    """Print one line per shipped scene; returns 0."""
    print("\n".join(lines()))
    return 0
