"""One self-contained HTML page of a finished run: data as inline JSON, the script and style of script.py."""
from __future__ import annotations

import html
import json
import math

import numpy as np

from .decimate import extremes, frame_limit, frames
from .drawing import FORCE_ARROW, draw
from .script import SCRIPT, STYLE

PLAY_SECONDS = 10.0   # play shows a run in about this many seconds (at least real time for a short run)


def _numbers(values) -> list:
    """Floats kept to 6 significant digits (a plot needs no more), NaN and inf as null."""
    return [float(f"{v:.6g}") if math.isfinite(v) else None for v in np.asarray(values, dtype=float).tolist()]


QUANTITY = {"N": "force", "N.m": "moment", "rad": "angle", "rad/s": "angular speed", "rad/s2": "angular acceleration",
            "m": "length", "m/s": "speed", "m/s2": "acceleration", "kg": "mass", "J": "energy", "W": "power",
            "s": "time", "1": "ratio"}
_DISPLAY = {"N": ("kN", 1e-3), "N.m": ("kN.m", 1e-3), "rad": ("deg", 180.0 / math.pi),
            "rad/s": ("deg/s", 180.0 / math.pi), "rad/s2": ("deg/s2", 180.0 / math.pi)}


def _axis(unit: str | None, column: str = "") -> tuple[str, float]:
    """Display unit and factor: forces in kN, angles in degrees, a drive's shaft speeds in rpm; None: the unit
    is not known."""
    if unit is None:
        return "unit unknown", 1.0
    if unit == "rad/s" and column.startswith("drive.") and column.endswith("_speed"):
        return "rpm", 60.0 / (2.0 * math.pi)
    return _DISPLAY.get(unit, (unit or "1", 1.0))


def _quantity(unit: str | None, column: str = "") -> str:
    """The quantity an axis shows, named (force, moment, angle, rotational speed...)."""
    if unit == "rad/s" and _axis(unit, column)[0] == "rpm":
        return "rotational speed"
    return QUANTITY.get(unit or "1", "value") if unit is not None else "value"


def plot_specs(result: np.ndarray, groups: list[tuple[str, list[str]]], units: dict[str, str],
               lines: dict[str, list[tuple[str, float]]] | None = None, *, extra: dict[str, np.ndarray] | None = None,
               dashed: set[str] | frozenset = frozenset(),
               marks: dict[str, list[tuple[float, str]]] | None = None) -> list[dict]:
    """One plot per (group, display unit): the series decimated keeping each bucket's extremes, in display units
    (kN, deg, rpm), the axis named by its quantity.  ``extra``: series by name that are not result columns (an
    operator command's values, one per row), ``dashed`` the names drawn dashed; ``marks``: vertical lines
    (t [s], label) by group title, those under '' on every plot (the events, where the run stopped)."""
    t = np.asarray(result["time"], dtype=float)
    extra = extra or {}
    marks = marks or {}
    out = []
    for title, cols in groups:
        by_unit: dict[tuple[str, str], list[str]] = {}
        for c in cols:
            by_unit.setdefault((_axis(units.get(c), c)[0], _quantity(units.get(c), c)), []).append(c)
        for (shown, quantity), names in by_unit.items():
            series = []
            for c in names:
                factor = _axis(units.get(c), c)[1]
                v = np.asarray(extra[c] if c in extra else result[c], dtype=float) * factor
                keep = extremes(v)
                series.append({"name": c, "t": _numbers(t[keep]), "v": _numbers(v[keep]), **(
                    {"dash": True} if c in dashed else {})})
            refs = [{"label": label, "v": value * _axis(units.get(c), c)[1]}
                    for c in names for label, value in (lines or {}).get(c, [])]
            at = [{"t": float(f"{when:.9g}"), "label": label} for when, label in [*marks.get(title, []),
                                                                                  *marks.get("", [])]]
            out.append({"title": title if len(by_unit) == 1 else f"{title} ({shown})", "unit": shown,
                        "ylabel": f"{quantity} [{shown}]", "series": series, "lines": refs, "marks": at})
    return out


def table(rows: list[tuple[str, ...]], head: tuple[str, ...] = ()) -> str:
    if not rows:
        return "<p class='note'>none</p>"
    th = "<tr>" + "".join(f"<th>{html.escape(h)}</th>" for h in head) + "</tr>" if head else ""
    return "<table>" + th + "".join("<tr>" + "".join(f"<td>{html.escape(str(c))}</td>" for c in r) + "</tr>"
                                    for r in rows) + "</table>"


def _in_degrees(value: float, unit: str) -> str:
    """' (x deg)' beside an angle in radians (as an operator reads it), else ''."""
    return f" ({math.degrees(value):.6g} deg)" if unit.strip() == "rad" and math.isfinite(value) else ""


def stop_line(stopped: str) -> str:
    """Why the run stopped before its stop time, in red under the title ('' if it ran to the end)."""
    return f"<p class='stop' id='stopped'>The run stopped early: {html.escape(stopped)}</p>" if stopped else ""


def verdict_block(assertions, stopped: str = "") -> str:
    """An experiment's verdict as the first thing a reader sees: PASS or FAIL in colour, how many passed,
    why the run stopped early (if it did), and each assertion with value, limit, margin and unit."""
    passed = all(v.passed for v in assertions)
    word = "PASS" if passed else "FAIL"
    good = sum(v.passed for v in assertions)
    stop = stop_line(stopped)
    rows = []
    for v in assertions:
        unit = f" {v.unit}" if getattr(v, "unit", "") and v.unit != "1" else ""
        value = ("-" if v.value != v.value else f"{v.value:.6g}{unit}" + _in_degrees(v.value, unit)) + (
            f" @ {v.time:.6g} s" if v.time is not None else "")
        margin = "-" if v.margin != v.margin or abs(v.margin) == math.inf else f"{v.margin:.6g}{unit}"
        result = "pass" if v.passed else "FAIL" + (f": {v.note}" if v.note else "")
        cells = (v.name, v.column, value, (v.limit + unit) if v.limit else "-", margin, result)
        rows.append(f"<tr class='{'pass' if v.passed else 'fail'}'>" + "".join(
            f"<td>{html.escape(str(c))}</td>" for c in cells) + "</tr>")
    head = "".join(f"<th>{h}</th>" for h in ("assertion", "of", "value", "limit", "margin", "result"))
    return (f"<div class='verdict {word.lower()}' id='verdict'><b>{word}</b>: {good} of {len(assertions)} "
            f"assertion(s) passed</div>{stop}<table class='assertions'><tr>{head}</tr>{''.join(rows)}</table>")


def page(result: np.ndarray, *, title: str, plots: list[dict], sections: list[tuple[str, str]],
         notes: list[str], verdict: str = "") -> str:
    """The HTML text: ``result`` (at least the drawn columns and time) animated, ``plots`` (plot_specs),
    ``sections`` (heading, HTML) below them; ``verdict`` (HTML, an experiment's) first, under the title."""
    t = np.asarray(result["time"], dtype=float)
    d = draw(result)
    idx = frames(len(t), frame_limit(3 * len(d.points) + len(d.forces)))
    duration = float(t[-1] - t[0]) if len(t) else 0.0
    data = {
        "frames": {"t": _numbers(t[idx]),
                   "points": {k: [_numbers(a[idx]) for a in xyz] for k, xyz in d.points.items()},
                   "forces": {k: _numbers(v[idx]) for k, v in d.forces.items()}},
        "elements": d.elements, "threeD": d.three_d, "closeup": d.closeup, "arrow": FORCE_ARROW, "plots": plots,
        "t0": float(t[0]) if len(t) else 0.0, "t1": float(t[-1]) if len(t) else 1.0,
        "speed": max(1.0, duration / PLAY_SECONDS),
    }
    blob = json.dumps(data, separators=(",", ":"), allow_nan=False).replace("</", "<\\/")
    every = "every output time" if len(idx) == len(t) else f"{len(idx)} of the {len(t)} output times, evenly spaced"
    body = "".join(f"<h2>{html.escape(h)}</h2>{content}" for h, content in sections)
    note_html = "".join(f"<p class='note'>{html.escape(n)}</p>" for n in [*d.notes, *notes])
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{html.escape(title)}</title>
<style>{STYLE}</style></head><body>
<h1>{html.escape(title)}</h1>
{verdict}
<h2>The crane</h2>
<div class="views" id="views"></div>
<div class="controls"><button id="play">play</button><input type="range" id="slider" min="0" value="0" step="1">
<span id="time"></span></div>
<p class="note">Frames: {every}.  Plots: each series keeps the smallest and largest value of each of its
time buckets.  Drag across a plot to zoom in, double-click to zoom out, click to move the slider there.</p>
{note_html}
<h2>Outputs</h2>
<div id="plots"></div>
{body}
<script type="application/json" id="report-data">{blob}</script>
<script>{SCRIPT}</script>
</body></html>
"""
