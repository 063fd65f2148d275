"""Test helper: write altered copies of a built .ssp/.fmu (a broken connection, a hostile entry, ...)."""
from __future__ import annotations

import zipfile
from pathlib import Path

from cranefmu import build as b

SCENE = "elastic_pendulum"


def scene_ssp() -> Path:
    """The built elastic_pendulum.ssp (built if stale)."""
    b.build(verbose=False, only=[SCENE])
    return b.SSP_DIR / f"{SCENE}.ssp"


def read_member(archive: Path, name: str) -> bytes:
    with zipfile.ZipFile(archive) as zf:
        return zf.read(name)


def repack(src: Path, dst: Path, replace: dict[str, bytes | None] | None = None,
           extra: list[tuple[zipfile.ZipInfo | str, bytes]] | None = None) -> Path:
    """Copy zip ``src`` to ``dst``, replacing (bytes) or dropping (None) members, then adding ``extra``."""
    replace = replace or {}
    with zipfile.ZipFile(src) as zin, zipfile.ZipFile(dst, "w", zipfile.ZIP_DEFLATED) as zout:
        for info in zin.infolist():
            if info.filename in replace:
                if replace[info.filename] is not None:
                    zout.writestr(info.filename, replace[info.filename])
            else:
                zout.writestr(info, zin.read(info.filename))
        for name, data in extra or []:
            zout.writestr(name, data)
    return dst


def edit_ssp(dst: Path, ssd=None, ssv=None, **kw) -> Path:
    """A copy of the scene's .ssp with its SSD and/or default SSV text passed through ``ssd(text)``/``ssv(text)``."""
    src = scene_ssp()
    replace = dict(kw.pop("replace", {}) or {})
    if ssd is not None:
        replace["SystemStructure.ssd"] = ssd(read_member(src, "SystemStructure.ssd").decode()).encode()
    if ssv is not None:
        replace["resources/default.ssv"] = ssv(read_member(src, "resources/default.ssv").decode()).encode()
    return repack(src, dst, replace, **kw)


def edit_fmu_in_ssp(dst: Path, member: str, replace: dict[str, bytes | None] | None = None,
                    extra: list[tuple[zipfile.ZipInfo | str, bytes]] | None = None) -> Path:
    """A copy of the scene's .ssp whose FMU ``member`` (e.g. resources/Rope.fmu) is altered."""
    src = scene_ssp()
    original, altered = dst.with_suffix(".orig.fmu"), dst.with_suffix(".new.fmu")
    original.write_bytes(read_member(src, member))
    repack(original, altered, replace, extra)
    inner = altered.read_bytes()
    original.unlink()
    altered.unlink()
    return repack(src, dst, {member: inner})


def symlink_entry(name: str, target: str) -> tuple[zipfile.ZipInfo, bytes]:
    """A zip entry that unpacks (with a Unix unzip) as a symbolic link ``name`` -> ``target``."""
    info = zipfile.ZipInfo(name)
    info.create_system = 3
    info.external_attr = (0o120777 << 16)
    return info, target.encode()
