"""A scene with a component that fails on purpose: elastic_pendulum plus the unconnected ``Faulty`` FMU."""
from __future__ import annotations

import zipfile
from pathlib import Path

HERE = Path(__file__).resolve().parent


def faulty_fmu(dest: Path) -> Path:
    """Build Faulty.fmu into ``dest`` once; returns its path."""
    from cranefmu.build import build_fmu

    fmu = Path(dest) / "Faulty.fmu"
    if not fmu.exists():
        fmu.parent.mkdir(parents=True, exist_ok=True)
        build_fmu(HERE / "Faulty.py", fmu)
    return fmu


def faulty_scene(src_ssp: Path, fmu: Path, dst: Path) -> Path:
    """``src_ssp`` with one more component ``faulty`` (source resources/Faulty.fmu, no connections)."""
    element = ('<ssd:Component name="faulty" source="resources/Faulty.fmu" '
               'type="application/x-fmu-sharedlibrary"/>\n      ')
    with zipfile.ZipFile(src_ssp) as zin, zipfile.ZipFile(dst, "w", zipfile.ZIP_DEFLATED) as zout:
        for info in zin.infolist():
            data = zin.read(info.filename)
            if info.filename == "SystemStructure.ssd":
                text = data.decode()
                text = text.replace("<ssd:Elements>", "<ssd:Elements>\n      " + element, 1)
                data = text.encode()
            zout.writestr(info, data)
        zout.write(fmu, "resources/Faulty.fmu")
    return dst
