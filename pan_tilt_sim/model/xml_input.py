"""Reading a description's XML: the steps the URDF and SDF readers share.

``parse_root`` parses the text and reports a malformed document as one line
naming the file and line; ``float_or_nan`` turns an element's text into a
float, anything ``float()`` refuses into NaN, so each reader checks one value
(finite? positive?) and words its own error, naming its file and element.
"""

from __future__ import annotations

import math
import pathlib
import xml.etree.ElementTree as ElementTree

from pan_tilt_sim.errors import DescriptionError


def parse_root(text: str, source: pathlib.Path) -> ElementTree.Element:
    """Return the root element of the XML ``text``; a malformed one names ``source``'s line."""
    try:
        return ElementTree.fromstring(text)
    except ElementTree.ParseError as err:
        line, _column = err.position
        raise DescriptionError(f'{source}:{line}: not well-formed XML: {err.msg}') from None


def float_or_nan(text: str) -> float:
    """Return ``text`` as a float; NaN where it is not a number."""
    try:
        return float(text)
    except ValueError:
        return math.nan
