"""``cranefmu report RESULT.csv`` and ``cranefmu run ... --report FILE``: the command-line side of the report."""
from __future__ import annotations

import argparse
import csv
from pathlib import Path

from ..errors import CraneFmuError


def _scene_of(header: list[str]) -> str:
    """The built-in scene whose run writes exactly these columns ('' if none does)."""
    from ..master.run import preview
    from ..scenes import SCENES

    for name in SCENES:
        try:
            if ["time", *preview(name).columns] == header:
                return name
        except CraneFmuError:   # a scene not built here: it cannot be the one
            continue
    return ""


def main(args: argparse.Namespace) -> int:
    from ..master.results import read_csv
    from ..master.run import preview
    from . import report_columns, write_report

    source = Path(args.result)
    output = Path(args.output) if args.output else source.with_suffix(".html")
    from ..whole_file import check

    check(output, "--output")
    try:
        with open(source, "rb") as f:
            header = next(csv.reader([f.readline().decode("utf-8")]), [])
    except OSError as err:
        raise CraneFmuError(f"RESULT {source} cannot be read: {err.strerror}") from None
    except UnicodeDecodeError:
        raise CraneFmuError(f"RESULT {source} is not allowed: line 1 is not UTF-8 text (a CSV of cranefmu run "
                            "--output is)") from None
    if "time" not in header:
        raise CraneFmuError(f"RESULT {source} is not allowed: no time column in its header (a CSV of cranefmu run "
                            "--output is)")
    scene = args.scene or _scene_of(header)
    units = preview(scene).units if scene else {}
    wanted = report_columns(scene, header[1:])
    try:
        data = read_csv(source, wanted)
    except (ValueError, UnicodeDecodeError, IndexError):
        raise CraneFmuError(f"RESULT {source} is not allowed: {_first_bad_cell(source, header, wanted)}") from None
    print(f"report: {write_report(output, data, scene=scene, units=units, source=source.name, what='--output')}")
    return 0


def _first_bad_cell(source: Path, header: list[str], wanted: list[str]) -> str:
    """Where the CSV ``source`` first holds something that is not a number in a column of ``wanted``."""
    index = [header.index(c) for c in ["time", *wanted] if c in header]
    with open(source, "rb") as f:
        for n, raw in enumerate(f, 1):
            if n == 1:
                continue
            try:
                cells = next(csv.reader([raw.decode("utf-8")]), [])
            except UnicodeDecodeError:
                return f"line {n} is not UTF-8 text (a CSV of cranefmu run --output is)"
            if len(cells) != len(header):
                return f"line {n} has {len(cells)} cells, the header {len(header)}"
            for i in index:
                try:
                    float(cells[i])
                except ValueError:
                    return f"line {n}, column {header[i]}: {cells[i][:40]!r} is not a number"
    return "it cannot be read as numbers"


def add_parser(sub) -> None:
    """Register ``cranefmu report``."""
    p = sub.add_parser("report", help="write the self-contained HTML report of a finished run's CSV "
                       "(docs/report.md)")
    p.add_argument("result", help="a CSV written by cranefmu run --output")
    p.add_argument("--scene", default=None, help="the scene that wrote it (default: the built-in scene with "
                   "exactly its columns, else none: generic plots, no units)")
    p.add_argument("--output", default=None, help="the HTML file (default: RESULT with .html)")


def add_run_option(parser) -> None:
    """``cranefmu run --report FILE``."""
    parser.add_argument("--report", default=None, metavar="FILE", help="write the run's self-contained HTML "
                        "report (crane animated, plots, settings, coupling health; docs/report.md)")


def report_after_run(path, res, scene, assertions=()) -> Path:
    """The report of a finished ``cranefmu run`` (``res`` a RunResult, ``scene`` its ScenePreview; an
    experiment's ``assertions`` verdicts); a run streamed to its CSV without keeping its rows is read back
    from the CSV (only the columns needed)."""
    from ..master.results import read_csv
    from . import report_columns, write_report

    data = res.result
    spec = getattr(res, "spec", None)
    if not len(data) and res.output:
        data = read_csv(res.output, report_columns(res.scene, scene.columns, getattr(spec, "commands", ())))
    return write_report(path, res if data is res.result else data, scene=res.scene, units=scene.units,
                        settings=res.settings, stats=res.stats, warnings=res.warnings,
                        sources=spec.sources if spec is not None else None,
                        assertions=assertions, what="--report", spec=spec)
