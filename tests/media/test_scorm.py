"""The SCORM 1.2 package of an offline page (issue 39), checked with the standard library's XML parser.

The SCORM 1.2 schema files (``imscp_rootv1p1p2.xsd``, ``adlcp_rootv1p2.xsd``) are not available offline, so the
manifest is checked against what ADL's *SCORM 1.2 Content Aggregation Model* (section 2.3, "Content Packaging")
requires of a package with one SCO, element by element:

- the zip holds ``imsmanifest.xml`` at its root, and every file a resource names;
- the root is ``manifest`` in the IMS CP 1.1.2 namespace ``http://www.imsproject.org/xsd/imscp_rootv1p1p2`` with an
  ``identifier``; ``xsi:schemaLocation`` names that namespace and ADL's ``http://www.adlnet.org/xsd/adlcp_rootv1p2``
  with their schema files;
- ``metadata`` has ``schema`` = "ADL SCORM" and ``schemaversion`` = "1.2";
- ``organizations`` has a ``default`` that is the ``identifier`` of one of its ``organization`` elements, which has a
  ``title`` and an ``item`` (with a ``title``) whose ``identifierref`` is a ``resource``'s ``identifier``;
- that ``resource`` has ``type="webcontent"``, ``adlcp:scormtype="sco"`` (the attribute in ADL's namespace) and an
  ``href`` (the launch file) that is in the zip and listed as one of its ``file`` elements;
- every ``identifier`` is unique and an XML ``ID`` (an NCName).
"""

from __future__ import annotations

import io
import re
import xml.etree.ElementTree as ET
import zipfile

import pytest

from tpm_viz.media.scorm import ADLCP, IMSCP, LAUNCH, XSI, identifier, manifest, scorm_package

NCNAME = re.compile(r"[A-Za-z_][A-Za-z0-9_.-]*")


def check_package(data: bytes) -> ET.Element:
    """Every requirement of the module docstring; returns the launch resource."""
    archive = zipfile.ZipFile(io.BytesIO(data))
    names = archive.namelist()
    assert "imsmanifest.xml" in names
    root = ET.fromstring(archive.read("imsmanifest.xml"))
    cp = f"{{{IMSCP}}}"
    assert root.tag == f"{cp}manifest" and root.get("identifier")
    location = root.get(f"{{{XSI}}}schemaLocation").split()
    pairs = dict(zip(location[::2], location[1::2], strict=True))
    assert pairs[IMSCP] == "imscp_rootv1p1p2.xsd" and pairs[ADLCP] == "adlcp_rootv1p2.xsd"
    assert root.findtext(f"{cp}metadata/{cp}schema") == "ADL SCORM"
    assert root.findtext(f"{cp}metadata/{cp}schemaversion") == "1.2"
    organizations = root.find(f"{cp}organizations")
    default = [
        o for o in organizations.findall(f"{cp}organization") if o.get("identifier") == organizations.get("default")
    ]
    assert len(default) == 1 and default[0].findtext(f"{cp}title")
    items = default[0].findall(f"{cp}item")
    assert items and all(item.findtext(f"{cp}title") for item in items)
    resources = {r.get("identifier"): r for r in root.findall(f"{cp}resources/{cp}resource")}
    sco = resources[items[0].get("identifierref")]
    assert sco.get("type") == "webcontent" and sco.get(f"{{{ADLCP}}}scormtype") == "sco"
    files = [f.get("href") for f in sco.findall(f"{cp}file")]
    assert sco.get("href") in files and set(files) <= set(names)
    identifiers = [e.get("identifier") for e in root.iter() if e.get("identifier") is not None]
    assert len(identifiers) == len(set(identifiers)) and all(NCNAME.fullmatch(i) for i in identifiers)
    return sco


def test_a_package_has_the_manifest_at_its_root_and_the_page_as_its_one_sco():
    page = "<!doctype html><html><body>the page</body></html>"
    data = scorm_package(page, "3. The circle at two speeds", "03-speed-0")
    sco = check_package(data)
    assert sco.get("href") == LAUNCH
    archive = zipfile.ZipFile(io.BytesIO(data))
    assert archive.namelist() == ["imsmanifest.xml", LAUNCH]
    assert archive.read(LAUNCH).decode() == page
    assert scorm_package(page, "3. The circle at two speeds", "03-speed-0") == data  # deterministic


@pytest.mark.parametrize(
    "title",
    ['<b>bold</b> & "quoted"', "수업 1: 직접 특이점", "]]> <!-- x --> <?pi?>"],
    ids=["markup", "korean", "cdata"],
)
def test_any_title_is_written_as_text_and_reads_back(title):
    root = ET.fromstring(manifest(title, "my lesson: 1/2").encode())
    assert [t.text for t in root.iter(f"{{{IMSCP}}}title")] == [title, title]
    check_package(scorm_package("x", title, "weird key ü 7"))


def test_identifiers_are_xml_ids_whatever_the_key():
    for key in ("01-direct-0", "7 lessons/ü", "", "..", "-"):
        assert NCNAME.fullmatch(identifier(key))
