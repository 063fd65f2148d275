"""The public face (issue 36): what ``import cranefmu`` offers, what ``cranefmu.master.run`` exports and which
modules are public (those a package's ``__all__`` names, from ``cranefmu.__all__`` down; every other module is
internal), listed here so that a name or module added to or dropped from them is a decision (this list changes
with it); every name the docs and README call on them resolves, and the docs import only public modules."""
from __future__ import annotations

import importlib
import inspect
import re
from pathlib import Path

import cranefmu
import cranefmu.master.run

ROOT = Path(__file__).resolve().parents[2]
MODULES = {"errors", "report", "master", "analysis", "physics", "adapter", "scenes"}     # public modules beside sweep
PUBLIC = {"simulate", "run", "resolve", "RunSpec", "Execution", "RunResult", "RunInterrupted", "Observer", "Command",
          "Source", "build", "sweep", "fmu_path", "__version__", *MODULES}
PUBLIC_MODULES = {"cranefmu", "cranefmu.errors", "cranefmu.report", "cranefmu.sweep", "cranefmu.master", "cranefmu.master.run",
                  "cranefmu.analysis", *(f"cranefmu.analysis.{m}" for m in ("reference", "modal", "sway_envelope",
                                                                            "stability", "fit_boucwen")),
                  "cranefmu.physics", *(f"cranefmu.physics.{m}" for m in (
                      "boom", "boucwen", "chassis", "chassis4", "component", "drive", "girder", "motion_laws", "params",
                      "pendulum", "rope", "slewing")),
                  "cranefmu.adapter", "cranefmu.adapter.fmi_adapter", "cranefmu.adapter.units", "cranefmu.scenes"}
PACKAGE = Path(cranefmu.__file__).parent
FUNCTIONS = {"cranefmu.build"}   # a function in __all__ whose name an internal module shares (made callable, as sweep)
MASTER_RUN = {"run", "simulate", "preview", "execute", "build_execution", "resolve", "RunSpec", "RunResult", "RunStats",
              "Settings", "Execution", "Observer", "Command", "Source", "ALGORITHMS", "RunInterrupted",
              "read_csv"}   # a run's CSV back as a structured array (docs/report.md)


def test_import_cranefmu_offers_the_listed_names():
    assert set(cranefmu.__all__) == PUBLIC
    assert all(getattr(cranefmu, name) is not None for name in PUBLIC)
    # nothing else public defined at the top (imported helpers excepted)
    loose = {n for n, v in vars(cranefmu).items() if not n.startswith("_") and not inspect.ismodule(v)}
    assert loose - PUBLIC <= {"annotations", "Path"}


def test_master_run_exports_the_listed_names():
    assert set(cranefmu.master.run.__all__) == MASTER_RUN
    assert all(hasattr(cranefmu.master.run, name) for name in MASTER_RUN)


def test_every_name_the_docs_call_is_public():
    text = "\n".join(p.read_text() for p in [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))])
    top = set(re.findall(r"\bcranefmu\.([A-Za-z]\w*)\(", text)) | {
        n.strip() for names in re.findall(r"from cranefmu import ([\w, ]+)", text) for n in names.split(",")}
    top = {n for n in top if not inspect.ismodule(getattr(cranefmu, n, None))}
    assert top and top <= PUBLIC, sorted(top - PUBLIC)
    master = set(re.findall(r"\bcranefmu\.master\.run\.([A-Za-z]\w*)", text))
    assert master <= MASTER_RUN, sorted(master - MASTER_RUN)


def _is_module(dotted: str) -> bool:
    path = PACKAGE.parent.joinpath(*dotted.split("."))
    return path.with_suffix(".py").is_file() or (path / "__init__.py").is_file()


def public_modules() -> set[str]:
    """The modules named by ``__all__`` from ``cranefmu`` down (a package's public modules are in its ``__all__``)."""
    found, todo = {"cranefmu"}, ["cranefmu"]
    while todo:
        package = importlib.import_module(todo.pop())
        if not hasattr(package, "__path__"):
            continue
        for name in getattr(package, "__all__", ()):
            dotted = f"{package.__name__}.{name}"
            if _is_module(dotted) and dotted not in found | FUNCTIONS:
                found.add(dotted)
                todo.append(dotted)
    return found


def test_the_public_modules_are_the_listed_ones():
    assert public_modules() == PUBLIC_MODULES
    assert all(importlib.import_module(m).__doc__ for m in PUBLIC_MODULES)
    every = {".".join(p.relative_to(PACKAGE.parent).with_suffix("").parts).removesuffix(".__init__")
             for p in PACKAGE.rglob("*.py") if "_sources" not in p.parts}
    assert PUBLIC_MODULES < every and len(every - PUBLIC_MODULES) > 100   # most modules are internal


def test_the_package_says_the_rest_is_internal():
    doc = cranefmu.__doc__
    assert "``__all__``" in doc and "Every other module is internal" in doc
    for package in ("master", "analysis", "physics", "adapter", "report", "compose", "experiments", "native", "studies",
                    "subcommands", "scenes"):
        assert "nternal" in importlib.import_module(f"cranefmu.{package}").__doc__, package


def test_the_docs_import_only_public_modules():
    text = "\n".join(p.read_text() for p in [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))])
    imported = set(re.findall(r"^\s*(?:>>> )?from (cranefmu(?:\.\w+)*) import", text, re.M)) | \
        set(re.findall(r"^\s*(?:>>> )?import (cranefmu(?:\.\w+)*)", text, re.M))
    assert imported and imported <= PUBLIC_MODULES, sorted(imported - PUBLIC_MODULES)


def test_build_stays_callable_after_its_module_is_imported(monkeypatch):
    """Importing cranefmu.build (a run by scene name does) bound the name cranefmu.build to the module, and the
    documented cranefmu.build() raised "'module' object is not callable"."""
    import cranefmu.build as module

    calls = []
    monkeypatch.setattr(module, "build", lambda *args, **kwargs: calls.append((args, kwargs)) or ["built"])
    assert cranefmu.build is module and cranefmu.build(force=False) == ["built"]
    assert calls == [((), {"force": False})]
