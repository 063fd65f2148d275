"""Untrusted input (an .ssp or .fmu from anywhere): safe zip extraction and guarded XML parsing.

Archives: :func:`safe_extract` refuses members that would land outside the target (absolute paths,
``..``, symbolic links) instead of letting zipfile rewrite them silently.

XML (SSD, SSV, modelDescription.xml): documents with a DTD are refused before anything reads them.

SSP and FMI files never need a document type declaration.  A DTD is how XML pulls in external
files (XXE: ``<!ENTITY x SYSTEM "file:///...">``) or expands a few bytes into gigabytes (nested
entities, "billion laughs").  The check parses with a parser that resolves no entities, loads no
DTD and touches no network, so the check itself is safe; fmpy (lxml with its defaults) only
ever sees documents that passed it.
"""
from __future__ import annotations

import re
import zipfile
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


def safe_extract(archive: Path, target: Path) -> None:
    """Extract a zip, refusing members that would land outside ``target`` (absolute, ``..``, links)."""
    target = target.resolve()
    with zipfile.ZipFile(archive) as zf:
        for info in zf.infolist():
            dest = (target / info.filename).resolve()
            if dest != target and target not in dest.parents:
                raise SceneError(f"{archive.name}: entry {info.filename!r} would be extracted outside "
                                 f"{target}; refusing the archive")
            if (info.external_attr >> 16) & 0o170000 == 0o120000:
                raise SceneError(f"{archive.name}: entry {info.filename!r} is a symbolic link; refusing the archive")
        zf.extractall(target)
