"""The layout (issue 36): test and benchmark scaffolding lives in support/cranefmu_support, which the
wheel does not ship and the shipped package never imports; the FMU adapter is the package cranefmu.adapter.
(The built wheel's file list is checked in test_installed.py; this is the cheap check on what setuptools finds.)"""
from __future__ import annotations

import ast
import tomllib
from pathlib import Path

from setuptools import find_packages

ROOT = Path(__file__).resolve().parents[2]
SCAFFOLDING = ("fmu_child", "foreign_ssp", "model_cases", "oscillator", "c_host", "c_fmu", "late")


def _packages() -> list[str]:
    """The packages the wheel ships, found as pyproject.toml tells setuptools to find them."""
    find = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["packages"]["find"]
    return [p for where in find["where"] for p in find_packages(str(ROOT / where))]


def test_the_wheel_finds_the_adapter_and_no_scaffolding():
    packages = _packages()
    assert "cranefmu.adapter" in packages and "cranefmu.studies" in packages
    assert not [p for p in packages if p.startswith("cranefmu_support") or p.split(".")[-1] in SCAFFOLDING]
    assert not [m for m in SCAFFOLDING if (ROOT / "src/cranefmu/studies" / m).exists()
                or (ROOT / "src/cranefmu/studies" / f"{m}.py").exists()]


def test_no_package_data_names_the_scaffolding():
    data = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["package-data"]
    assert not [pattern for patterns in data.values() for pattern in patterns if any(m in pattern for m in SCAFFOLDING)]


def test_the_scaffolding_is_in_the_support_package():
    import cranefmu_support.model_cases

    support = ROOT / "support" / "cranefmu_support"
    assert Path(cranefmu_support.model_cases.__file__).resolve().parent == support
    assert all((support / m).is_dir() or (support / f"{m}.py").is_file() for m in SCAFFOLDING)


def test_the_shipped_package_never_imports_the_support_package():
    wrong = []
    for path in sorted((ROOT / "src" / "cranefmu").rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            names = ([node.module or ""] if isinstance(node, ast.ImportFrom) else
                     [a.name for a in node.names] if isinstance(node, ast.Import) else [])
            wrong += [f"{path.relative_to(ROOT)}:{node.lineno}" for n in names if n.split(".")[0] == "cranefmu_support"]
    assert not wrong, wrong


ANALYSES = ("reference", "modal", "converge", "scene_questions", "sway_envelope", "stability", "fit_boucwen",
            "seed_figures")


def test_the_crane_analyses_are_one_package():
    """The analyses (the monolith, modes, convergence, a scene's question, sway envelope, stability limit, Bouc-Wen
    fit, the seeds' figures) are cranefmu.analysis, not loose among the top-level modules (issue 36)."""
    package = ROOT / "src" / "cranefmu"
    assert "cranefmu.analysis" in _packages()
    assert all((package / "analysis" / f"{m}.py").is_file() for m in ANALYSES)
    assert not [m for m in ANALYSES if (package / f"{m}.py").exists()]


SCENE_MODULES = ("catalog", "docs", "info")


def test_the_scene_modules_are_one_package():
    """The named scenes' code is cranefmu.scenes (its __init__ the summaries and measures; catalog, info, docs beside
    it), not four loose scene*.py modules at the top (issue 36); the old paths hold no shim."""
    package = ROOT / "src" / "cranefmu"
    assert "cranefmu.scenes" in _packages()
    assert all((package / "scenes" / f"{m}.py").is_file() for m in SCENE_MODULES)
    assert not [p.name for p in package.glob("scene*.py")]
