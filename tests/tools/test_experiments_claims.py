"""Every number docs/validation.md quotes in its tables is asserted by an experiment or excused.

docs/experiments.md's claims table maps each column of each validation.md table (a table is named by its
first and last column header) to the experiment files that assert it, or gives the reason it has none.
A number counts as asserted when an assertion of a named file quotes it in its ``source`` and carries it
in its limit: the number (as written, or in SI against the doc's kN / mm / %: times 10^k, k = -6..6 in
steps of 3, or -2), rounded as the doc writes it, overlaps the limit's tolerance band or holds a number
written in its limit expression or its case's ``set``.  A number is matched against every assertion of
the row's files, not one case (a cell cannot be tied to a case without parsing the row's labels).
Numbers the row excuses by name ("not asserted: ...") are skipped.  The text (prose) of validation.md
is not parsed: its numbers are listed in the second table, whose rows are checked the same way.  No FMU
runs here: tests/tools/test_experiments_check.py runs experiments/ (CI).
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass
from pathlib import Path

import pytest

try:
    import tomllib
except ModuleNotFoundError:   # Python 3.10
    import tomli as tomllib

ROOT = Path(__file__).resolve().parents[2]
VALIDATION = ROOT / "docs" / "validation.md"
EXPERIMENTS_DOC = ROOT / "docs" / "experiments.md"
TABLES_HEADING = "## Which assertion checks which number of docs/validation.md"
TEXT_HEADING = "### Numbers in validation.md's text"
# a number as the docs write it: not part of a word (HC1, luff30) or of a version (13001-2 is two tokens)
NUMBER = re.compile(r"(?<![\w.])[-+]?\d+(?:\.\d+)?(?:e[-+]?\d+)?(?!\w)(?!\.\d)")
TICKED = re.compile(r"`([^`]+)`")
# the docs' units against the files' SI (kN -> N, mm -> m, % -> 1, ...)
SCALES = (1.0, 1e3, 1e-3, 1e-2, 1e6, 1e-6)


def numbers(text: str) -> list[str]:
    """The numbers written in ``text``, as written (a leading ~ or sign dropped: '~0.6' -> '0.6')."""
    return [m.group(0).lstrip("+-") for m in NUMBER.finditer(text)]


def markdown_tables(text: str) -> list[tuple[list[str], list[list[str]]]]:
    """(header cells, rows of cells) of every table of a markdown text."""
    lines, out, i = text.splitlines(), [], 0
    while i < len(lines):
        if lines[i].startswith("|") and i + 1 < len(lines) and set(lines[i + 1].replace("|", "").strip()) <= set("-: "):
            cells = lambda s: [c.strip() for c in s.strip().strip("|").split("|")]   # noqa: E731
            head, j, rows = cells(lines[i]), i + 2, []
            while j < len(lines) and lines[j].startswith("|"):
                rows.append(cells(lines[j]))
                j += 1
            out.append((head, rows))
            i = j
        else:
            i += 1
    return out


def section(text: str, heading: str) -> str:
    """The part of ``text`` from ``heading`` to the next heading of the same or a higher level."""
    start = text.index(heading)
    level = len(heading) - len(heading.lstrip("#"))
    end = re.compile(rf"^#{{1,{level}}} ", re.M).search(text, start + len(heading))
    return text[start:end.start() if end else len(text)]


@dataclass(frozen=True)
class Asserted:
    """What one assertion of an experiment file commits to."""

    where: str                        # file / case / name
    quoted: frozenset[float]          # the numbers its source quotes
    bands: tuple[tuple[float, float], ...]   # [lo, hi] its numeric limits accept
    written: frozenset[float]         # numbers written in its limit expressions and its case's set

    def asserts(self, number: str) -> bool:
        """Whether this assertion quotes ``number`` (as the docs write it) and holds it in its limit."""
        x = float(number)
        half = 0.5 * 10.0 ** -_decimals(number)   # a rounded value: half its last digit
        if not any(abs(q - x) <= half * (1 + 1e-9) for q in self.quoted):   # quoted as written, or finer
            return False
        for scale in SCALES:
            y = x * scale
            r = half * scale * (1 + 1e-9) + 1e-9 * abs(y)     # the doc's rounding overlaps the band
            if any(lo - r <= y <= hi + r for lo, hi in self.bands):
                return True
            if any(abs(y - w) <= half * scale * (1 + 1e-9) for w in self.written):
                return True
        return False


def _decimals(number: str) -> int:
    """Digits after the point of a number as written ('7.553' -> 3, '55052' -> 0, '17.07e-3' -> 5)."""
    mantissa, _, exponent = number.lower().partition("e")
    digits = len(mantissa.partition(".")[2])
    return digits - int(exponent or 0)


def _same(a: float, b: float) -> bool:
    return math.isclose(a, b, rel_tol=1e-9, abs_tol=1e-12)


def _floats(value) -> list[float]:
    if isinstance(value, bool):
        return []
    if isinstance(value, (int, float)):
        return [float(value)]
    if isinstance(value, str):
        return [float(n) for n in numbers(value)]
    return []


def assertions_of(path: Path) -> list[Asserted]:
    """The assertions of an experiment file, each with its case's ``set`` (cases inherit the base's)."""
    data = tomllib.loads(path.read_text(encoding="utf-8"))
    cases = data.get("cases") or {"base": {}}
    out = []
    for case_name, case in cases.items():
        given = {**data.get("set", {}), **case.get("set", {})}
        for a in [*data.get("assert", []), *case.get("assert", [])]:
            bands, written = [], [v for x in given.values() for v in _floats(x)]
            for key in ("equals", "min", "max"):
                if isinstance(a.get(key), str):
                    written += _floats(a[key])
            eq = a.get("equals")
            if isinstance(eq, (int, float)) and not isinstance(eq, bool):
                tol = max(a.get("abs", 0.0), a.get("rel", 0.0) * abs(eq))
                bands.append((eq - tol, eq + tol))
            lo, hi = a.get("min"), a.get("max")
            if isinstance(lo, (int, float)) or isinstance(hi, (int, float)):
                bands.append((lo if isinstance(lo, (int, float)) else -math.inf,
                              hi if isinstance(hi, (int, float)) else math.inf))
            out.append(Asserted(f"{path.relative_to(ROOT)} / {case_name} / {a.get('name', '?')}",
                                frozenset(_floats(a.get("source", ""))), tuple(bands), frozenset(written)))
    return out


@dataclass(frozen=True)
class Claim:
    """One row of docs/experiments.md's claims tables."""

    key: str                 # table rows: 'first … last' header of the validation.md table; text rows: the label
    columns: tuple[str, ...]  # table rows: the columns it covers; text rows: ()
    quoted: tuple[str, ...]   # text rows: the numbers it lists
    files: tuple[str, ...]
    why: str                  # the case / assertion cell (names, or why not asserted)

    @property
    def excused(self) -> set[str]:
        """Numbers this row names as not asserted ('not asserted: ...' to the end of the cell)."""
        at = self.why.find("not asserted")
        return set(numbers(self.why[at:])) if at >= 0 else set()


def claims() -> tuple[list[Claim], list[Claim]]:
    """(table rows, text rows) of docs/experiments.md's claims tables."""
    text = EXPERIMENTS_DOC.read_text(encoding="utf-8")
    found = markdown_tables(section(text, TABLES_HEADING))
    assert len(found) >= 2, f"docs/experiments.md: '{TABLES_HEADING}' needs its two tables (tables, text)"
    (_, table_rows), (_, text_rows) = found[0], found[1]
    files = lambda cell: tuple(f for f in TICKED.findall(cell) if f.endswith(".toml"))   # noqa: E731
    tables = [Claim(" … ".join(TICKED.findall(r[0])), tuple(TICKED.findall(r[1])), (), files(r[2]), r[3])
              for r in table_rows]
    prose = [Claim(r[0], (), tuple(numbers(r[1])), files(r[2]), r[3]) for r in text_rows]
    return tables, prose


def validation_columns() -> dict[tuple[str, str], list[str]]:
    """('first … last' header, column header) -> the numbers written in that column of validation.md."""
    out: dict[tuple[str, str], list[str]] = {}
    for head, rows in markdown_tables(VALIDATION.read_text(encoding="utf-8")):
        key = f"{head[0]} … {head[-1]}"
        for i, column in enumerate(head):
            out.setdefault((key, column), []).extend(n for r in rows if i < len(r) for n in numbers(r[i]))
    return out


def _check(claim: Claim, quoted: list[str]) -> list[str]:
    """The numbers of ``quoted`` that no assertion of the claim's files asserts (and the row does not excuse)."""
    if not claim.files:
        return []
    asserted = [a for f in claim.files for a in assertions_of(ROOT / "experiments" / f)]
    return [n for n in quoted if n not in claim.excused and not any(a.asserts(n) for a in asserted)]


def test_number_parser_reads_the_docs_forms():
    assert numbers("yes, at t = 9.25 s, boom 15.93 m") == ["9.25", "15.93"]
    assert numbers("1.307 (1.31, 1.29, 1.32) | ~0.6 | -2.7 % | 7.55 .. 11.33 | HC1 luff30 6.05023") == \
        ["1.307", "1.31", "1.29", "1.32", "0.6", "2.7", "7.55", "11.33", "6.05023"]
    assert numbers("17.07e-3 and 1.1e-14") == ["17.07e-3", "1.1e-14"]


def test_every_validation_table_column_has_a_claims_row():
    tables, _ = claims()
    covered = {(c.key, col) for c in tables for col in c.columns}
    missing = [f"{k[0]!r} column {k[1]!r}" for k in validation_columns() if k not in covered]
    assert not missing, ("docs/validation.md table columns without a row in docs/experiments.md's claims table: "
                         + "; ".join(missing))
    stale = sorted(f"{k[0]!r} column {k[1]!r}" for k in covered - set(validation_columns()))
    assert not stale, "docs/experiments.md's claims table names columns docs/validation.md lacks: " + "; ".join(stale)


def test_claims_rows_name_existing_files_and_give_a_reason_when_none():
    tables, prose = claims()
    for c in tables + prose:
        for f in c.files:
            assert (ROOT / "experiments" / f).is_file(), f"claims row {c.key!r}: no file experiments/{f}"
        if not c.files:
            assert len(c.why) >= 6, f"claims row {c.key!r} names no file and gives no reason"


def _rows():
    tables, prose = claims()
    columns = validation_columns()
    return ([pytest.param(c, [n for col in c.columns for n in columns.get((c.key, col), [])],
                          id=f"{c.key.split(' … ')[0]}:{'+'.join(c.columns)}"[:80]) for c in tables if c.files] +
            [pytest.param(c, list(c.quoted), id=f"text:{c.key}"[:80]) for c in prose if c.files])


@pytest.mark.parametrize("claim, quoted", _rows())
def test_every_claimed_number_is_asserted(claim, quoted):
    """Each number of the row is quoted by an assertion's source and inside its limit (module docstring)."""
    missing = _check(claim, quoted)
    assert not missing, (f"docs/validation.md {claim.key!r} {list(claim.columns) or ''}: no assertion in "
                         f"{', '.join(claim.files)} asserts {', '.join(missing)} (source quoting it and a limit "
                         "holding it), and the claims row does not excuse it")


def test_the_check_fails_on_a_number_no_assertion_holds(tmp_path, monkeypatch):
    """On purpose: a quoted number outside every assertion's limit, or quoted by none, is reported."""
    exp = tmp_path / "experiments"
    exp.mkdir()
    (exp / "x.toml").write_text('scene = "hook_sway"\n[[assert]]\nname = "a"\ncolumn = "boom.x_tip"\n'
                                'equals = 104.13e3\nrel = 0.001\nsource = "104.13 kN, model 104.16 kN, 9.03 mm"\n')
    monkeypatch.setattr(__import__(__name__), "ROOT", tmp_path)
    row = Claim("t", ("c",), (), ("x.toml",), "`a`")
    assert _check(row, ["104.13", "104.16", "104.5", "9.03", "1.92"]) == ["104.5", "9.03", "1.92"]
    row = Claim("t", ("c",), (), ("x.toml",), "`a`; not asserted: 9.03 (the paper's misprint)")
    assert _check(row, ["9.03"]) == []
