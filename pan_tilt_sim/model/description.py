"""The description layer: a .urdf or .xacro file to a :class:`RobotDescription`.

Nothing here knows about PyBullet or ROS: it reads the file (running xacro
with the user's mappings when the file is a xacro), parses it once into the
robot model (:mod:`pan_tilt_sim.model.urdf`), and makes PyBullet's copy of the
URDF, whose meshes are local files PyBullet can load
(:mod:`pan_tilt_sim.model.resources`) and whose links without ``<inertial>``
are explicitly massless (:mod:`pan_tilt_sim.model.inertials`).
"""

from __future__ import annotations

import contextlib
import dataclasses
import io
import pathlib
import xml.etree.ElementTree as ElementTree
from collections.abc import Sequence
from xml.parsers.expat import ExpatError

from pan_tilt_sim.errors import DescriptionError, one_line
from pan_tilt_sim.model.inertials import complete_inertials
from pan_tilt_sim.model.resources import localize_meshes, mesh_cache_dir
from pan_tilt_sim.model.robot import JointKind, JointSpec, RobotModel
from pan_tilt_sim.model.sdf import is_sdf_text, sdf_robot_to_urdf
from pan_tilt_sim.model.urdf import parse_xml, read_model

XACRO_SUFFIX = '.xacro'
MAPPING_SEPARATOR = ':='
# Lines xacro adds after a warning to say where it was.
XACRO_LOCATION_PREFIXES = ('when processing file:', 'included from:')


@dataclasses.dataclass(frozen=True)
class RobotDescription:
    """A robot description, read once: its model, its URDF as written, PyBullet's copy.

    ``urdf_xml`` is the URDF as the user wrote it (xacro's output, meshes
    still ``package://...``): what robot_description publishes and
    robot_state_publisher and RViz read.  ``physics_urdf`` is PyBullet's
    copy, whose meshes point at loadable local files, whose massless
    links say so and whose joint axes are unit vectors.
    """

    model: RobotModel
    urdf_xml: str
    physics_urdf: str
    # The file it was read from; for a description taken from a topic, the topic's name.
    source: pathlib.Path
    # What xacro warned about while expanding the file ("redefining global
    # symbol: pi"...) and what making PyBullet's copy had to change (a frozen
    # joint's massless links), one line each, for the caller to log once.
    warnings: tuple[str, ...] = ()

    @property
    def name(self) -> str:
        """The robot's name."""
        return self.model.name

    @property
    def joints(self) -> tuple[JointSpec, ...]:
        """All joints, in file order."""
        return self.model.joints

    @property
    def actuated_joints(self) -> tuple[JointSpec, ...]:
        """Joints a one-degree-of-freedom controller can drive (non-fixed)."""
        return self.model.actuated_joints

    @property
    def plugin_namespace(self) -> str | None:
        """The ``robotNamespace`` of the URDF's gazebo_ros_control plugin, if any."""
        return self.model.plugin_namespace


def parse_xacro_args(xacro_args: Sequence[str]) -> dict[str, str]:
    """Turn ``['name:=value', ...]`` into xacro mappings."""
    mappings = {}
    for item in xacro_args:
        name, separator, value = item.partition(MAPPING_SEPARATOR)
        if not separator or not name:
            raise DescriptionError(
                f"xacro_args: '{item}' is not of the form name:=value")
        mappings[name] = value
    return mappings


def run_xacro(path: pathlib.Path, mappings: dict[str, str]) -> tuple[str, tuple[str, ...]]:
    """Expand a xacro file with ``mappings``; return the URDF and xacro's warnings.

    xacro prints its warnings on stderr; they are captured instead, so that
    a failed start-up prints only its one error line and a good one can log
    them through the node's logger.  Errors name the file and line.
    """
    import xacro  # deferred: only xacro files need it

    captured = io.StringIO()
    try:
        with contextlib.redirect_stderr(captured):
            document = xacro.process_file(str(path), mappings=mappings)
    except ExpatError as err:
        raise DescriptionError(
            f'{path}:{err.lineno}: not well-formed XML: {_expat_reason(err)}') from None
    except xacro.XacroException as err:
        raise DescriptionError(f'{path}: xacro error: {one_line(str(err))}') from None
    except Exception as err:  # xacro surfaces NameError, KeyError... from user expressions
        raise DescriptionError(
            f'{path}: xacro error: {type(err).__name__}: {one_line(str(err))}') from None
    return document.toprettyxml(indent='  '), xacro_warnings(path, captured.getvalue())


def xacro_warnings(path: pathlib.Path, text: str) -> tuple[str, ...]:
    """Fold what xacro printed into one line per warning, each naming the file once.

    xacro follows a warning with the file it was processing ("when
    processing file: ...", "included from: ..."); that is kept only where it
    names another file than ``path`` (an included one).
    """
    warnings: list[str] = []
    for line in text.splitlines():
        line = line.strip()
        if not line:
            continue
        if line.startswith(XACRO_LOCATION_PREFIXES) and warnings:
            if line.partition(':')[2].strip() != str(path):
                warnings[-1] += f' ({line})'
            continue
        warnings.append(f'{path}: xacro: {line}')
    return tuple(dict.fromkeys(warnings))


def read_description_xml(path: pathlib.Path,
                         xacro_args: Sequence[str] = ()) -> tuple[str, tuple[str, ...]]:
    """Return the URDF text of a .urdf or .xacro file, and xacro's warnings."""
    if path.is_dir():
        raise DescriptionError(f'robot description file {path}: is a directory, not a file')
    if not path.is_file():
        raise DescriptionError(f'robot description file {path}: no such file')
    mappings = parse_xacro_args(xacro_args)
    if path.suffix == XACRO_SUFFIX or mappings:
        return run_xacro(path, mappings)
    try:
        text = path.read_text(encoding='utf-8')
    except (OSError, UnicodeDecodeError) as err:
        raise DescriptionError(f'robot description file {path}: cannot read: {err}') from None
    if 'xmlns:xacro' in text and '<xacro:' in text:
        # A URDF-named file that uses xacro macros: expand it, as `xacro` would.
        return run_xacro(path, mappings)
    return text, ()


def load_description(path: pathlib.Path | str, xacro_args: Sequence[str] = ()) -> RobotDescription:
    """Read a .urdf/.xacro file into a :class:`RobotDescription` (parsed once)."""
    path = pathlib.Path(path).expanduser().resolve()
    urdf_xml, warnings = read_description_xml(path, xacro_args)
    return _description(urdf_xml, path, path.parent, warnings)


def description_from_text(urdf_xml: str, source: str,
                          base_dir: pathlib.Path | None = None) -> RobotDescription:
    """Read URDF text (xacro's output, as robot_state_publisher publishes it) into a description.

    ``source`` names where the text came from in errors and log lines (the
    robot_description topic's name); ``package://`` and ``file://`` meshes
    resolve as from a file, relative ones from ``base_dir`` (default: the
    current directory, where a launch file runs).
    """
    base = pathlib.Path.cwd() if base_dir is None else base_dir
    return _description(urdf_xml, pathlib.Path(source), base, ())


def _description(urdf_xml: str, source: pathlib.Path, base_dir: pathlib.Path,
                 warnings: tuple[str, ...]) -> RobotDescription:
    if is_sdf_text(urdf_xml):
        urdf_xml, warnings = sdf_as_urdf(urdf_xml, source, base_dir, warnings)
    root = parse_xml(urdf_xml, source)
    model = read_model(root, source)
    if not model.actuated_joints:
        raise DescriptionError(f'{source}: the robot has no movable joints to control')
    # The model was read before, so it keeps the URIs as written.
    physics_urdf, physics_warnings = physics_copy(root, model, base_dir, source)
    return RobotDescription(
        model=model,
        urdf_xml=published_urdf(urdf_xml, model),
        physics_urdf=physics_urdf,
        source=source,
        warnings=warnings + physics_warnings,
    )


def sdf_as_urdf(text: str, source: pathlib.Path, base_dir: pathlib.Path,
                warnings: tuple[str, ...] = ()) -> tuple[str, tuple[str, ...]]:
    """Return the URDF an SDF robot becomes (:mod:`pan_tilt_sim.model.sdf`), and the warnings."""
    conversion = sdf_robot_to_urdf(text, source, base_dir)
    return conversion.urdf_xml, warnings + conversion.warnings


def published_urdf(urdf_xml: str, model: RobotModel) -> str:
    """Return the URDF robot_description publishes: ``urdf_xml``, its ball joints made fixed.

    A ball joint (PyBullet's ``spherical``, from an SDF) is no URDF joint type
    robot_state_publisher and RViz know; as a fixed joint they show its link
    where it is mounted.
    """
    if not any(joint.kind is JointKind.SPHERICAL for joint in model.joints):
        return urdf_xml
    root = ElementTree.fromstring(urdf_xml)
    for element in root.findall('joint'):
        if element.get('type') == JointKind.SPHERICAL.value:
            element.set('type', JointKind.FIXED.value)
    return ElementTree.tostring(root, encoding='unicode')


def physics_copy(root: ElementTree.Element, model: RobotModel, base_dir: pathlib.Path,
                 source: pathlib.Path) -> tuple[str, tuple[str, ...]]:
    """Turn the parsed tree into PyBullet's copy; return its text and what had to change.

    Every mesh made loadable (relative ones taken from ``base_dir``), every
    massless link explicit and every moving joint's axis a unit vector; errors
    name ``source``.  Also used for the
    objects spawned into the world (:mod:`pan_tilt_sim.model.entity_resource`).
    """
    try:
        localize_meshes(root, base_dir, mesh_cache_dir())
    except DescriptionError as err:
        raise DescriptionError(f'{source}: {err}') from None
    warnings = complete_inertials(root, model)
    unit_axes(root, model)
    # One element per line: PyBullet's reader fails on some long one-line files
    # ("Cannot load URDF file."), which minified URDFs would be.
    ElementTree.indent(root)
    return ElementTree.tostring(root, encoding='unicode'), warnings


def unit_axes(root: ElementTree.Element, model: RobotModel) -> None:
    """Write each moving joint's axis into PyBullet's copy (``root``) as the model's unit vector.

    URDF means the axis as a direction; PyBullet would take its length too
    (see :mod:`pan_tilt_sim.model.urdf`).  Joints without ``<axis>`` keep
    URDF's default, a unit vector already.
    """
    for element in root.findall('joint'):
        axis = element.find('axis')
        joint = model.joint(element.get('name', ''))
        if axis is not None and joint.kind.is_actuated:
            axis.set('xyz', ' '.join(repr(value) for value in joint.axis))


def _expat_reason(err: ExpatError) -> str:
    from xml.parsers.expat import ErrorString
    return ErrorString(err.code)
