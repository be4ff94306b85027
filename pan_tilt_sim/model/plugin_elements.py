"""The robot's model-level Gazebo ``<plugin>`` elements, read once, as data. No ROS.

Every ``<gazebo><plugin>`` without a ``reference`` (URDF), and every model
``<plugin>`` of an SDF (which :mod:`~pan_tilt_sim.model.sdf` turns into
those), becomes one :class:`PluginElement`: its ``filename`` and ``name``
attributes, its child elements' texts and its ``<ros>`` block, and the file
it came from.  What a plugin makes of them -- which elements it reads, their
defaults and checks -- is the plugin's own element spec
(:mod:`pan_tilt_sim.plugins`); the model knows no plugin.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from xml.etree import ElementTree

from pan_tilt_sim.model.sensors import plugin_stem


@dataclasses.dataclass(frozen=True)
class PluginElement:
    """One ``<plugin>`` element: attributes, child texts, ``<ros>`` block, source file.

    ``values`` maps each child element's tag to its texts (stripped), in
    document order (a tag may repeat: ``left_joint``).  ``ros_namespace`` and
    ``ros_remappings`` are the ``<ros>`` block's ``<namespace>`` and
    ``<remapping>`` texts as written; ``has_ros`` says whether it has one.
    """

    filename: str
    name: str = ''
    values: Mapping[str, tuple[str, ...]] = dataclasses.field(default_factory=dict)
    has_ros: bool = False
    ros_namespace: str = ''
    ros_remappings: tuple[str, ...] = ()
    source: str = ''

    @property
    def stem(self) -> str:
        """The file name without ``lib`` and ``.so`` (``gazebo_ros_diff_drive``)."""
        return plugin_stem(self.filename)


def read_plugin_elements(root: ElementTree.Element, source: object) -> tuple[PluginElement, ...]:
    """Return the ``<gazebo><plugin>`` elements (no ``reference``) of ``root``, in order."""
    elements = []
    for gazebo in root.findall('gazebo'):
        if gazebo.get('reference') is not None:
            continue
        for element in gazebo.findall('plugin'):
            values: dict[str, list[str]] = {}
            for child in element:
                values.setdefault(child.tag, []).append((child.text or '').strip())
            ros = element.find('ros')
            elements.append(PluginElement(
                filename=element.get('filename', ''), name=element.get('name', ''),
                values={tag: tuple(texts) for tag, texts in values.items()},
                has_ros=ros is not None,
                ros_namespace=(ros.findtext('namespace') or '').strip() if ros is not None
                else '',
                ros_remappings=tuple((child.text or '').strip() for child in ros.findall(
                    'remapping')) if ros is not None else (),
                source=str(source)))
    return tuple(elements)
