"""Untrusted input (an .ssp or .fmu from anywhere): safe zip extraction and guarded XML parsing.

Archives: :func:`safe_extract` refuses members that would land outside the target (absolute paths,
``..``, symbolic links) instead of letting zipfile rewrite them silently, and archives that would
unpack to more than ``CRANEFMU_EXTRACT_LIMIT_MB`` (default 512 MiB) or whose members expand more
than ``CRANEFMU_EXTRACT_RATIO`` times (default 200; a zip bomb).

XML (SSD, SSV, modelDescription.xml): documents with a DTD are refused before anything reads them.

SSP and FMI files never need a document type declaration.  A DTD is how XML pulls in external
files (XXE: ``<!ENTITY x SYSTEM "file:///...">``) or expands a few bytes into gigabytes (nested
entities, "billion laughs").  The check parses with a parser that resolves no entities, loads no
DTD and touches no network, so the check itself is safe; fmpy (lxml with its defaults) only
ever sees documents that passed it.
"""
from __future__ import annotations

import os
import re
import zipfile
import zlib
from pathlib import Path

from ..errors import SceneError

_DOCTYPE = re.compile(rb"<!DOCTYPE", re.IGNORECASE)
_DTD_REFUSED = ("{} declares a document type (<!DOCTYPE ...>): not allowed, SSP and FMI XML needs no DTD "
                "or entities (refused against external-entity and entity-expansion attacks)")
XML_SUFFIXES = (".ssd", ".ssv", ".ssm", ".ssb", ".xml")


def _parser():
    from lxml import etree

    return etree.XMLParser(resolve_entities=False, no_network=True, load_dtd=False, huge_tree=False,
                           dtd_validation=False)


def parse_xml(path: Path):
    """The root element of an XML file already passed by :func:`check_xml_files`, read with the
    same parser (no entities, no network, no DTD)."""
    from lxml import etree

    return etree.parse(str(path), _parser()).getroot()


def check_xml(data: bytes, where: str):
    """The root element of ``data``; raise :class:`SceneError` if it is not well-formed XML or
    declares a DTD or entities."""
    from lxml import etree

    if _DOCTYPE.search(data):  # before parsing: an entity bomb is refused without being expanded
        raise SceneError(_DTD_REFUSED.format(where))
    try:
        root = etree.fromstring(data, _parser())
    except etree.XMLSyntaxError as err:
        raise SceneError(f"{where} is not well-formed XML: {err}") from None
    doc = root.getroottree().docinfo
    if doc.internalDTD is not None or doc.externalDTD is not None or doc.doctype:
        raise SceneError(_DTD_REFUSED.format(where))
    return root


def check_xml_files(directory: Path, label: str) -> None:
    """Check every SSP/FMI XML file under ``directory`` (an extracted archive named ``label``)."""
    directory = Path(directory)
    for path in sorted(directory.rglob("*")):
        if path.suffix.lower() in XML_SUFFIXES and path.is_file():
            check_xml(path.read_bytes(), f"{label}: {path.relative_to(directory).as_posix()}")


LIMIT_ENV = "CRANEFMU_EXTRACT_LIMIT_MB"   # the most an archive may unpack to [MiB]
RATIO_ENV = "CRANEFMU_EXTRACT_RATIO"      # the most one member may expand over its compressed size
LIMIT_MB = 512.0   # every scene of cranefmu unpacks to under 10 MiB; an FMU with big binaries, some 100
RATIO = 200.0      # deflate on real files: 2-10x; a zip bomb's zeros: ~1000x
RATIO_FROM = 1 << 20   # members smaller than this are never refused for their ratio


def _limit(name: str, default: float) -> float:
    text = os.environ.get(name, "")
    if not text:
        return default
    try:
        value = float(text)
    except ValueError:
        value = -1.0
    if not value > 0:
        raise SceneError(f"{name} = {text!r} is not allowed: give a positive number")
    return value


def check_sizes(zf: zipfile.ZipFile, label: str) -> None:
    """Refuse an archive whose members would unpack to more than the limits (declared sizes:
    zipfile never extracts more than a member declares)."""
    limit, ratio = _limit(LIMIT_ENV, LIMIT_MB), _limit(RATIO_ENV, RATIO)
    total = sum(info.file_size for info in zf.infolist())
    if total > limit * 2 ** 20:
        raise SceneError(f"{label} unpacks to {total / 2 ** 20:.1f} MiB, more than the limit of {limit:g} MiB "
                         f"(refused as a possible zip bomb); set {LIMIT_ENV} to raise it")
    for info in zf.infolist():
        if info.file_size >= RATIO_FROM and info.file_size > ratio * max(info.compress_size, 1):
            raise SceneError(f"{label}: entry {info.filename!r} expands {info.file_size / max(info.compress_size, 1):.0f}"
                             f" times ({info.compress_size} to {info.file_size} bytes), more than {ratio:g} "
                             f"(refused as a possible zip bomb); set {RATIO_ENV} to raise it")


def safe_extract(archive: Path, target: Path, skip: tuple[str, ...] = ()) -> None:
    """Extract a zip, refusing members that would land outside ``target`` (absolute, ``..``, links),
    an archive over the size limits (:func:`check_sizes`) and a file that is not a zip archive.
    Members whose names start with one of ``skip`` (e.g. ``"sources/"``) are checked but not written."""
    target = target.resolve()
    try:
        with zipfile.ZipFile(archive) as zf:
            for info in zf.infolist():
                dest = (target / info.filename).resolve()
                if dest != target and target not in dest.parents:
                    raise SceneError(f"{archive.name}: entry {info.filename!r} would be extracted outside "
                                     f"{target}; refusing the archive")
                if (info.external_attr >> 16) & 0o170000 == 0o120000:
                    raise SceneError(f"{archive.name}: entry {info.filename!r} is a symbolic link; refusing the archive")
            check_sizes(zf, archive.name)
            zf.extractall(target, [i for i in zf.infolist() if not i.filename.startswith(skip)] if skip else None)
    except (zipfile.BadZipFile, zipfile.LargeZipFile, EOFError, NotImplementedError, zlib.error) as err:
        raise SceneError(f"{archive} is not a readable zip archive ({err}): an .ssp or .fmu must be one") from None
