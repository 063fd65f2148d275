"""Untrusted .ssp/.fmu files: no entry lands outside its target directory, no XML entity is resolved.

fmpy 0.3.32's ``extract`` refuses only leading slashes, drive letters and backslashes; a ``../``
entry is silently rewritten by zipfile.  The master extracts both the .ssp and every FMU in it
with its own ``safe_extract`` (refuses the archive) and checks every SSD, SSV and
modelDescription.xml for a DTD before fmpy's lxml parser reads it.
"""
from __future__ import annotations

import zipfile
from pathlib import Path

import pytest

from cranefmu.errors import SceneError
from cranefmu.master.run import run
from cranefmu.master.untrusted import safe_extract
from cranefmu.master.untrusted import check_xml

from scene_edit import edit_fmu_in_ssp, edit_ssp, repack, scene_ssp, symlink_entry

README = Path(__file__).resolve().parents[2] / "README.md"

XXE = b"""<?xml version="1.0"?>
<!DOCTYPE r [<!ENTITY x SYSTEM "file://{secret}">]>
<r>&x;</r>
"""


def billion_laughs(levels: int = 9) -> bytes:
    text = '<?xml version="1.0"?>\n<!DOCTYPE lolz [\n<!ENTITY l0 "lollollollollollollollollollol">\n'
    for i in range(1, levels + 1):
        text += f'<!ENTITY l{i} "' + f"&l{i - 1};" * 10 + '">\n'
    return (text + f"]>\n<r>&l{levels};</r>\n").encode()


def _zip(path: Path, entries: list) -> Path:
    with zipfile.ZipFile(path, "w") as zf:
        zf.writestr("ok.txt", b"fine")
        for name, data in entries:
            zf.writestr(name, data)
    return path


@pytest.mark.parametrize("entry", ["../escaped.txt", "sub/../../escaped.txt", "/tmp/cranefmu_abs_escaped.txt"])
def test_safe_extract_refuses_entries_outside_the_target(tmp_path, entry):
    archive = _zip(tmp_path / "evil.zip", [(entry, b"pwned")])
    target = tmp_path / "inside" / "target"
    target.mkdir(parents=True)
    with pytest.raises(SceneError, match="outside") as err:
        safe_extract(archive, target)
    assert repr(entry) in str(err.value) and "evil.zip" in str(err.value)
    # refused as a whole: nothing written anywhere, not even the harmless member
    assert not list(target.iterdir())
    assert not (tmp_path / "inside" / "escaped.txt").exists() and not (tmp_path / "escaped.txt").exists()
    assert not Path("/tmp/cranefmu_abs_escaped.txt").exists()


def test_safe_extract_refuses_symbolic_links(tmp_path):
    archive = _zip(tmp_path / "link.zip", [symlink_entry("resources/passwd", "/etc/passwd")])
    with pytest.raises(SceneError, match="symbolic link") as err:
        safe_extract(archive, tmp_path / "t")
    assert "'resources/passwd'" in str(err.value)


def test_safe_extract_extracts_an_ordinary_archive(tmp_path):
    archive = _zip(tmp_path / "good.zip", [("a/b/c.txt", b"deep")])
    safe_extract(archive, tmp_path / "t")
    assert (tmp_path / "t" / "a" / "b" / "c.txt").read_bytes() == b"deep"


def test_ssp_with_an_escaping_entry_is_refused(built, tmp_path):
    ssp = repack(scene_ssp(), tmp_path / "evil.ssp", extra=[("../../escaped_from_ssp.txt", b"pwned")])
    with pytest.raises(SceneError, match="outside") as err:
        run(ssp, stop_time=0.01, step_size=1e-3)
    assert "'../../escaped_from_ssp.txt'" in str(err.value)


def test_fmu_inside_an_ssp_with_an_escaping_entry_is_refused(built, tmp_path):
    ssp = edit_fmu_in_ssp(tmp_path / "evil_fmu.ssp", "resources/Rope.fmu",
                          extra=[("../../../escaped_from_fmu.txt", b"pwned")])
    with pytest.raises(SceneError) as err:
        run(ssp, stop_time=0.01, step_size=1e-3)
    msg = str(err.value)
    assert "component 'rope'" in msg and "'../../../escaped_from_fmu.txt'" in msg and "outside" in msg


def test_fmu_with_a_symlink_entry_is_refused(built, tmp_path):
    ssp = edit_fmu_in_ssp(tmp_path / "link_fmu.ssp", "resources/Pendulum.fmu",
                          extra=[symlink_entry("resources/evil", "/etc")])
    with pytest.raises(SceneError, match="symbolic link") as err:
        run(ssp, stop_time=0.01, step_size=1e-3)
    assert "component 'pendulum'" in str(err.value)


def test_check_xml_refuses_external_entity_without_reading_it(tmp_path):
    secret = tmp_path / "secret.txt"
    secret.write_text("TOP_SECRET_42")
    with pytest.raises(SceneError, match="DOCTYPE") as err:
        check_xml(XXE.replace(b"{secret}", str(secret).encode()), "x.ssd")
    assert "TOP_SECRET_42" not in str(err.value)


def test_check_xml_refuses_entity_expansion_and_accepts_plain_xml():
    with pytest.raises(SceneError, match="DOCTYPE"):
        check_xml(billion_laughs(), "bomb.ssv")
    check_xml((Path(__file__).resolve().parents[2] / "ssp/elastic_pendulum/SystemStructure.ssd").read_bytes(),
              "ok.ssd")
    with pytest.raises(SceneError, match="not well-formed"):
        check_xml(b"<a><b></a>", "broken.ssd")


def _with_doctype(text: str, doctype: str) -> str:
    head, sep, rest = text.partition("?>")
    return head + sep + "\n" + doctype + rest


def test_ssd_with_xxe_is_refused_before_fmpy_reads_it(built, tmp_path):
    secret = tmp_path / "secret.txt"
    secret.write_text("TOP_SECRET_42")
    doctype = f'<!DOCTYPE x [<!ENTITY leak SYSTEM "file://{secret}">]>'
    ssp = edit_ssp(tmp_path / "xxe.ssp",
                   ssd=lambda t: _with_doctype(t, doctype).replace('description="load', 'description="&leak; load'))
    with pytest.raises(SceneError, match="DOCTYPE") as err:
        run(ssp, stop_time=0.01, step_size=1e-3)
    assert "SystemStructure.ssd" in str(err.value) and "TOP_SECRET_42" not in str(err.value)


def test_ssv_with_billion_laughs_is_refused(built, tmp_path):
    bomb = billion_laughs().decode().split("<r>")[0].split("?>")[1].strip()  # just the DOCTYPE block
    ssp = edit_ssp(tmp_path / "bomb.ssp", ssv=lambda t: _with_doctype(t, bomb))
    with pytest.raises(SceneError, match="DOCTYPE") as err:
        run(ssp, stop_time=0.01, step_size=1e-3)
    assert "resources/default.ssv" in str(err.value)


def test_model_description_with_xxe_is_refused(built, tmp_path):
    src = scene_ssp()
    with zipfile.ZipFile(src) as zf, zipfile.ZipFile(zf.open("resources/Rope.fmu")) as fmu:
        md = fmu.read("modelDescription.xml").decode()
    md = _with_doctype(md, '<!DOCTYPE fmiModelDescription [<!ENTITY e SYSTEM "file:///etc/hostname">]>')
    ssp = edit_fmu_in_ssp(tmp_path / "xxe_md.ssp", "resources/Rope.fmu", replace={"modelDescription.xml": md.encode()})
    with pytest.raises(SceneError, match="DOCTYPE") as err:
        run(ssp, stop_time=0.01, step_size=1e-3)
    assert "component 'rope'" in str(err.value) and "modelDescription.xml" in str(err.value)


def test_readme_says_an_fmu_runs_code_and_must_be_trusted():
    text = " ".join(README.read_text().split())
    assert "An FMU runs Python code: use FMUs and `.ssp` files only from a source you trust." in text
