"""Safe XML parsing for files that come from users.

Mechanism files are untrusted: external entities are never resolved and any
entity declaration (the basis of "billion laughs" expansion bombs) is refused
before anything is expanded.  defusedxml does this on top of the standard
library parser.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

import defusedxml
import defusedxml.ElementTree as SafeET

from .errors import MechanismFileError

__all__ = ["parse_xml_text"]


def parse_xml_text(text: str, path) -> ET.Element:
    """Parse ``text`` (the contents of ``path``) and return the root element."""
    if not text.strip():
        raise MechanismFileError(path, "the file is empty")
    try:
        return SafeET.fromstring(text, forbid_dtd=False, forbid_entities=True, forbid_external=True)
    except defusedxml.EntitiesForbidden:
        raise MechanismFileError(path, "XML entity declarations are not allowed (refused for safety)") from None
    except defusedxml.ExternalReferenceForbidden:
        raise MechanismFileError(path, "XML external references are not allowed (refused for safety)") from None
    except defusedxml.DTDForbidden:  # pragma: no cover - forbid_dtd is False
        raise MechanismFileError(path, "XML document type declarations are not allowed") from None
    except ET.ParseError as exc:
        raise MechanismFileError(path, f"malformed XML: {exc}") from None
