"""The public face (issue 36): what ``import cranefmu`` offers and what ``cranefmu.master.run`` exports, listed
here so that a name added to or dropped from either is a decision (this list changes with it); every name
the docs and README call on either resolves."""
from __future__ import annotations

import inspect
import re
from pathlib import Path

import cranefmu
import cranefmu.master.run

ROOT = Path(__file__).resolve().parents[2]
PUBLIC = {"simulate", "run", "resolve", "RunSpec", "Execution", "RunResult", "RunInterrupted", "Observer", "Command",
          "Source", "build", "sweep", "fmu_path", "__version__"}
MASTER_RUN = {"run", "simulate", "preview", "execute", "build_execution", "resolve", "RunSpec", "RunResult", "RunStats",
              "Settings", "Execution", "Observer", "Command", "Source", "ALGORITHMS", "RunInterrupted"}


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
