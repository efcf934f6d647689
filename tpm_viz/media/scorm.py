"""The offline lesson page as a SCORM 1.2 package: ``imsmanifest.xml`` and the page, zipped for an LMS.

A SCORM 1.2 package (ADL, *SCORM Content Aggregation Model* 1.2, section 2.3) is a zip file with ``imsmanifest.xml``
at its root: an IMS Content Packaging 1.1.2 manifest with ADL's extensions. :func:`manifest` writes the smallest one
an LMS imports: ``metadata`` (``schema`` "ADL SCORM", ``schemaversion`` "1.2"), one ``organization`` (the default)
with one ``item`` that points at one ``resource`` of ``type="webcontent"`` and ``adlcp:scormtype="sco"`` whose
``href`` is the page (the launch file) and which lists it as its one ``file``; the namespaces are IMS CP 1.1.2's
(``http://www.imsproject.org/xsd/imscp_rootv1p1p2``) and ADL CP 1.2's (``http://www.adlnet.org/xsd/adlcp_rootv1p2``),
with their ``xsi:schemaLocation``. The schema files themselves (``imscp_rootv1p1p2.xsd``, ``adlcp_rootv1p2.xsd``,
``ims_xml.xsd``) are not shipped: LMSs carry their own copies, and they are not available to this project offline.

The page inside the package reports to the LMS through the run-time API itself (``page_scorm.js``).
:func:`scorm_package` is deterministic: the same page and lesson give the same bytes (fixed entry times, fixed order).
"""

from __future__ import annotations

import io
import re
import xml.etree.ElementTree as ET
import zipfile

__all__ = ["ADLCP", "IMSCP", "LAUNCH", "XSI", "identifier", "manifest", "scorm_package"]

IMSCP = "http://www.imsproject.org/xsd/imscp_rootv1p1p2"
"""IMS Content Packaging 1.1.2: the manifest's default namespace in SCORM 1.2."""
ADLCP = "http://www.adlnet.org/xsd/adlcp_rootv1p2"
"""ADL's content packaging extensions for SCORM 1.2 (``adlcp:scormtype``)."""
XSI = "http://www.w3.org/2001/XMLSchema-instance"
SCHEMA_LOCATION = f"{IMSCP} imscp_rootv1p1p2.xsd {ADLCP} adlcp_rootv1p2.xsd"
LAUNCH = "index.html"
"""The page's name in the package: the SCO's launch file."""
_EPOCH = (1980, 1, 1, 0, 0, 0)


def identifier(text: str) -> str:
    """An XML ``ID`` (an NCName) made from ``text``: letters, digits, ``-``, ``_``, ``.``, starting with a letter."""
    cleaned = re.sub(r"[^A-Za-z0-9_.-]+", "-", text).strip("-") or "lesson"
    return f"tpm-viz-{cleaned}"


def manifest(title: str, key: str, launch: str = LAUNCH) -> str:
    """``imsmanifest.xml`` of a one-page package for the lesson ``key`` titled ``title`` (module docstring)."""
    ET.register_namespace("", IMSCP)
    ET.register_namespace("adlcp", ADLCP)
    ET.register_namespace("xsi", XSI)
    base = identifier(key)
    root = ET.Element(
        f"{{{IMSCP}}}manifest",
        {"identifier": f"{base}-manifest", "version": "1.0", f"{{{XSI}}}schemaLocation": SCHEMA_LOCATION},
    )
    metadata = ET.SubElement(root, f"{{{IMSCP}}}metadata")
    ET.SubElement(metadata, f"{{{IMSCP}}}schema").text = "ADL SCORM"
    ET.SubElement(metadata, f"{{{IMSCP}}}schemaversion").text = "1.2"
    organizations = ET.SubElement(root, f"{{{IMSCP}}}organizations", {"default": f"{base}-org"})
    organization = ET.SubElement(organizations, f"{{{IMSCP}}}organization", {"identifier": f"{base}-org"})
    ET.SubElement(organization, f"{{{IMSCP}}}title").text = title
    item = ET.SubElement(
        organization,
        f"{{{IMSCP}}}item",
        {"identifier": f"{base}-item", "identifierref": f"{base}-page", "isvisible": "true"},
    )
    ET.SubElement(item, f"{{{IMSCP}}}title").text = title
    resources = ET.SubElement(root, f"{{{IMSCP}}}resources")
    resource = ET.SubElement(
        resources,
        f"{{{IMSCP}}}resource",
        {"identifier": f"{base}-page", "type": "webcontent", f"{{{ADLCP}}}scormtype": "sco", "href": launch},
    )
    ET.SubElement(resource, f"{{{IMSCP}}}file", {"href": launch})
    ET.indent(root)
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="unicode") + "\n"


def _entry(name: str) -> zipfile.ZipInfo:
    info = zipfile.ZipInfo(name, _EPOCH)
    info.compress_type = zipfile.ZIP_DEFLATED
    info.external_attr = 0o644 << 16
    return info


def scorm_package(page: str, title: str, key: str) -> bytes:
    """The zip file an LMS imports: ``imsmanifest.xml`` at the root and the page as :data:`LAUNCH`."""
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w") as archive:
        archive.writestr(_entry("imsmanifest.xml"), manifest(title, key).encode("utf-8"))
        archive.writestr(_entry(LAUNCH), page.encode("utf-8"))
    return buffer.getvalue()
