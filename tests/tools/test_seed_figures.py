"""One value per seed figure (issue 37: seed 001's loose-rope factor was 1.55 on docs/studies/dynamic_factor.md
and 1.517 on docs/studies/validation.md): every generated page and every experiment quotes the figure of
``cranefmu.analysis.seed_figures``; docs/validation.md keeps its hand-written sections when it is regenerated."""
from __future__ import annotations

import importlib.util
import re
from pathlib import Path

import pytest

from cranefmu.analysis import seed_figures as seed
from cranefmu.studies import dynamic_factor, validation

try:
    import tomllib
except ModuleNotFoundError:   # Python 3.10
    import tomli as tomllib

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"
pytestmark = pytest.mark.skipif(not (DOCS / "validation.md").is_file(), reason="needs the checkout (docs/)")


def test_table7_is_the_mean_of_its_three_tests():
    assert seed.table7("tight") == pytest.approx((1.31 + 1.29 + 1.32) / 3, rel=1e-15)
    assert seed.table7("loose") == pytest.approx((1.55 + 1.45 + 1.55) / 3, rel=1e-15)
    assert f"{seed.table7('tight'):.3f}" == "1.307" and f"{seed.table7('loose'):.3f}" == "1.517"
    with pytest.raises(ValueError, match=r"start = 'slack' is not a Table 7 case: one of tight, loose"):
        seed.table7("slack")


def test_the_studies_take_the_measured_value_from_the_table():
    assert dynamic_factor.MEASURED == {0.0: seed.table7("tight"), 0.1: seed.table7("loose")}
    assert dynamic_factor.V_NOMINAL == seed.HOOK_SPEED
    rows = [{"model": "kelvin_voigt", "v_h": seed.HOOK_SPEED, "slack": s, "status": "ok", "dynamic_factor": f,
             "lift_off_time": 0.5, "error": ""} for s, f in ((0.0, 1.272), (0.1, 1.516))]
    text = "\n".join(dynamic_factor.page(rows, {"kelvin_voigt": {"beta2": 0.8, "phi2_min": 1.1, "class": "HC4"}}))
    # before: "slack 0.1 m 1.516 (measured 1.55, -2.2 %)", the first test instead of Table 7's mean
    assert "tight 1.272 (measured 1.307, -2.7 %)" in text and "slack 0.1 m 1.516 (measured 1.517, -0.0 %)" in text
    assert [validation.START[p] for p in ("default", "loose")] == ["tight", "loose"]


def _figures(page: str, text: str) -> dict[str, set[str]]:
    """{figure: the values ``text`` quotes for it} for the seed figures a page of docs/ can quote."""
    found: dict[str, set[str]] = {}
    if page == "studies/dynamic_factor.md":
        for start, value in re.findall(r"(tight|slack 0\.1 m) [\d.]+ \(measured ([\d.]+),", text):
            found.setdefault("table7 " + ("tight" if start == "tight" else "loose"), set()).add(value)
    if page in ("studies/validation.md", "validation.md"):
        # | rope | start ... | ... | measured ... |: the tight / loose row's Table 7 column
        for line in text.splitlines():
            cells = [c.strip() for c in line.strip("|").split("|")]
            if len(cells) >= 5 and cells[1].split(" ")[0] in ("tight", "loose"):
                col = 2 if page.startswith("studies/") else 4
                found.setdefault(f"table7 {cells[1].split(' ')[0]}", set()).add(cells[col].split(" ")[0])
    if page == "validation.md":
        for name, key in (("N2", "rear outrigger N2 (boom side)"), ("N1", "front outrigger N1"),
                          ("q2", "settlement rear q2"), ("q1", "settlement front q1")):
            m = re.search(rf"\| {re.escape(key)} \| [^|]+ \| ([\d.]+) (kN|mm) \|", text)
            if m:
                found.setdefault(name, set()).add(m.group(1))
        for v, paper in re.findall(r"^\| (0\.\d+) \| [\d.]+ \| [\d.]+ \| [\d.]+ \| ~([\d.]+) \|$", text, re.M):
            found.setdefault(f"sway {v}", set()).add(paper)
        m = re.search(r"printed ([\d.]+) mm, the formula gives", text)
        if m:
            found.setdefault("x_s0", set()).add(m.group(1))
    return found


def _table() -> dict[str, float]:
    """The seed figures as the pages write them (kN, mm, deg)."""
    out = {f"table7 {s}": seed.table7(s) for s in seed.TABLE7_TESTS}
    out.update(N2=seed.STATIC_REACTIONS["N2_rear"] / 1e3, N1=seed.STATIC_REACTIONS["N1_front"] / 1e3,
               q2=seed.STATIC_SETTLEMENTS["q2_rear"] * 1e3, q1=seed.STATIC_SETTLEMENTS["q1_front"] * 1e3,
               x_s0=seed.ROPE_STRETCH_PRINTED * 1e3)
    out.update({f"sway {v:g}": paper for v, paper in seed.SWAY_BY_SPEED.items()})
    return out


PAGES = ("studies/dynamic_factor.md", "studies/validation.md", "validation.md")


def test_the_page_parser_finds_every_quoted_figure_and_a_wrong_one():
    """The parser this file's check rests on reads a wrong value where a page would print one."""
    wrong = "kelvin_voigt at 0.208 m/s against seed 001 Table 7: slack 0.1 m 1.516 (measured 1.55, -2.2 %)."
    assert _figures("studies/dynamic_factor.md", wrong) == {"table7 loose": {"1.55"}}
    found = _figures("validation.md", (DOCS / "validation.md").read_text())
    assert set(found) == {"table7 tight", "table7 loose", "N2", "N1", "q2", "q1", "x_s0", "sway 0.2", "sway 0.35",
                          "sway 0.55"}


@pytest.mark.parametrize("page", PAGES)
def test_every_generated_page_quotes_the_tables_value(page):
    table = _table()
    found = _figures(page, (DOCS / page).read_text())
    assert found, f"docs/{page}: no seed figure found (the parser no longer reads the page)"
    for figure, values in found.items():
        want = table[figure]
        half = [0.5 * 10.0 ** -len(v.split(".")[-1]) if "." in v else 0.5 for v in values]   # as rounded
        assert len(values) == 1 and all(abs(float(v) - want) <= h + 1e-12 for v, h in zip(values, half)), \
            f"docs/{page}: {figure} quoted as {values}, the table has {want}"


def test_the_pages_agree_with_each_other():
    quoted: dict[str, set[str]] = {}
    for page in PAGES:
        for figure, values in _figures(page, (DOCS / page).read_text()).items():
            quoted.setdefault(figure, set()).update(float(v) for v in values)
    assert {f: v for f, v in quoted.items() if len(v) > 1} == {}
    assert quoted["table7 loose"] == {round(seed.table7("loose"), 3)}


def _assertions():
    for path in sorted((ROOT / "experiments").rglob("*.toml")):
        data = tomllib.loads(path.read_text())
        for case in data.get("cases", {}).values():
            for a in case.get("assert", []):
                yield path.relative_to(ROOT), a


def test_every_experiment_asserts_the_tables_value():
    """An assertion against a seed figure carries the table's value (as the pages quote it)."""
    checked = 0
    for path, a in _assertions():
        src = a.get("source", "")
        if src.startswith("seed 001 Table 7") and "equals" in a:
            start = "tight" if "tight" in src else "loose"
            assert a["equals"] == round(seed.table7(start), 3), f"{path}: {a['name']} {a['equals']}"
            checked += 1
        for key, value in (("N = 104.13 kN", seed.STATIC_REACTIONS["N2_rear"]),
                           ("seed 000: 77.8 kN", seed.STATIC_REACTIONS["N1_front"]),
                           ("settlement 2.57 mm", seed.STATIC_SETTLEMENTS["q2_rear"]),
                           ("settlement 1.92 mm", seed.STATIC_SETTLEMENTS["q1_front"]),
                           ("Fig. 3b: about 1.5 deg", seed.SWAY_BY_SPEED[0.35]),
                           ("about 0.6 deg", seed.SWAY_BY_SPEED[0.2])):
            if src.startswith("seed 000") and key in src:
                assert a["equals"] == pytest.approx(value, rel=1e-12), f"{path}: {a['name']} {a['equals']}"
                checked += 1
    assert checked >= 12


def _report():
    spec = importlib.util.spec_from_file_location("validation_report_script",
                                                  ROOT / "benchmarks" / "validation_report.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_validation_md_regenerated_keeps_its_hand_written_sections(tmp_path):
    """Every section of docs/validation.md that no script computes is in docs/validation_discussion.md,
    which the report appends whole (the truck_slewing section was only in the page: a regeneration
    dropped it)."""
    discussion = (DOCS / "validation_discussion.md").read_text()
    page = (DOCS / "validation.md").read_text()
    assert "## truck_slewing: slewing on four outriggers" in discussion
    assert page.endswith("\n\n" + discussion)   # the page is the generated part + the discussion, nothing else
    report = _report()
    made = report.assemble(["# Validation against the papers", "", "generated"],
                           DOCS / "validation_discussion.md")
    assert made == "# Validation against the papers\n\ngenerated\n\n" + discussion
    generated = page[: -len(discussion)]
    sections = re.findall(r"^##+ (.+)$", generated, re.M)
    code = (ROOT / "benchmarks" / "validation_report.py").read_text()
    assert all(s.split(":")[0].split(" (")[0] in code for s in sections), sections
