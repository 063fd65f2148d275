"""Which kind of FMU a scene holds, read from each FMU's ``generationTool``: cranefmu's pythonfmu FMUs
(``python``), its native C FMUs (``native``), or neither (another tool's, or a mix: None)."""
from __future__ import annotations

import re
from pathlib import Path

KINDS = ("native", "python")
_TOOL = re.compile(rb'generationTool\s*=\s*"([^"]*)"')


def kind_of_tool(tool: str) -> str | None:
    """``python`` for pythonfmu's generationTool ("PythonFMU 0.7.0"), ``native`` for cranefmu's native
    layer ("cranefmu 0.1.0 native FMI 2.0 layer ..."), None for any other."""
    if tool.lower().startswith("pythonfmu"):
        return "python"
    if tool.startswith("cranefmu") and "native" in tool:
        return "native"
    return None


def fmu_kind(unzipdir: Path) -> str | None:
    """The kind of the FMU unzipped in ``unzipdir`` (its modelDescription.xml's generationTool)."""
    with open(Path(unzipdir) / "modelDescription.xml", "rb") as f:
        found = _TOOL.search(f.read(8192))   # an attribute of the root element, near the top
    return kind_of_tool(found.group(1).decode(errors="replace")) if found else None


def scene_kind(unzipdirs: list[Path]) -> str | None:
    """``native`` or ``python`` if every FMU unzipped in ``unzipdirs`` is of that kind, else None."""
    kinds = {fmu_kind(d) for d in unzipdirs}
    return kinds.pop() if len(kinds) == 1 else None
