"""A rosbag2 bag folder in MCAP storage, laid out as rosbag2 (jazzy) lays one out.

A :class:`BagWriter` makes the folder ``<folder>/`` with ``<name>_0.mcap``
(``<name>`` is the folder's own name) and, when closed, ``metadata.yaml``,
as ``ros2 bag record -s mcap -o <folder>`` does (see the design notes).

Design notes: docs/design/ros.md#bagpy.
"""

from __future__ import annotations

import contextlib
import json
import os
import pathlib
import re
import sys
import threading
from collections.abc import Callable, Mapping, Sequence
from typing import IO, Any

import yaml

from pan_tilt_sim.errors import ConfigurationError, one_line

STORAGE_IDENTIFIER = 'mcap'
METADATA_FILE = 'metadata.yaml'
METADATA_VERSION = 9  # rosbag2_storage's BagMetadata version in jazzy
ROS_DISTRO = 'jazzy'
PROFILE = 'ros2'
SERIALIZATION_FORMAT = 'cdr'
DEFINITION_ENCODING = 'ros2msg'
# What rosbag2 writes when it finds no definition for a type.
UNKNOWN_ENCODING = 'unknown'
# rosbag2_storage_mcap's writer defaults: chunks, no compression (the cheapest to write).
CHUNK_SIZE = 1024 * 1024  # bytes of messages gathered before a chunk goes to the file
MCAP_HINT = 'recording needs the mcap package: pip install mcap'
DELIMITER = '=' * 80 + '\n'
# The field types a .msg line names, as rosbag2's local definition source finds them
# (comments and constants of primitive types never match a message type).
FIELD_TYPE = re.compile(r'(?:^|\n)\s*([a-zA-Z0-9_/]+)(?:\[[^\]]*\])?\s+')
TYPE_NAME = re.compile(r'^([a-zA-Z0-9_]+)/(?:msg/)?([a-zA-Z0-9_]+)$')
PRIMITIVE_TYPES = frozenset({
    'bool', 'byte', 'char', 'float32', 'float64', 'int8', 'uint8', 'int16', 'uint16',
    'int32', 'uint32', 'int64', 'uint64', 'string'})
MAX_NESTING = 50  # levels of nested types before a definition is taken to be circular


def package_share(package: str) -> pathlib.Path | None:
    """Return ``share/<package>`` of an installed package (ament index, else this prefix)."""
    try:
        from ament_index_python.packages import get_package_share_directory

        return pathlib.Path(get_package_share_directory(package))
    except (ImportError, LookupError, ValueError, OSError):
        # Not indexed (AMENT_PREFIX_PATH unset): where pip puts the ROS wheels' data files.
        installed = pathlib.Path(sys.prefix, 'share', package)
        return installed if installed.is_dir() else None


def _split(type_name: str) -> tuple[str, str] | None:
    match = TYPE_NAME.match(type_name)
    return (match.group(1), match.group(2)) if match else None


def _msg_text(type_name: str) -> str | None:
    split = _split(type_name)
    share = package_share(split[0]) if split else None
    if share is None:
        return None
    try:
        return (share / 'msg' / f'{split[1]}.msg').read_text()
    except OSError:
        return None


def _dependencies(text: str, package: str) -> list[str]:
    """Return the message types a .msg text names, package-qualified, in rosbag2's order."""
    found = set()
    for match in FIELD_TYPE.finditer(text):
        name = match.group(1)
        if name in PRIMITIVE_TYPES:
            continue
        found.add(name if '/' in name else f'{package}/{name}')
    return sorted(found)


def message_definition(type_name: str) -> tuple[str, str]:
    """Return ``(encoding, text)`` of ``type_name`` (``pkg/msg/Type``) as rosbag2 stores it.

    The type's ``.msg`` text, then each type it uses (depth first, each once,
    in sorted order at each level) after a delimiter line of 80 ``=`` and
    ``MSG: pkg/Type``.  ``('unknown', '')`` when the type's package or file
    is not installed, as rosbag2 writes then.
    """
    seen: set[str] = set()

    def full_text(name: str, depth: int) -> str | None:
        if depth > MAX_NESTING:
            return None
        text = _msg_text(name)
        if text is None:
            return None
        result = text
        for dependency in _dependencies(text, _split(name)[0]):
            if dependency in seen:
                continue
            seen.add(dependency)
            nested = full_text(dependency, depth + 1)
            if nested is None:
                return None
            result += f'\n{DELIMITER}MSG: {dependency}\n{nested}'
        return result

    text = full_text(type_name, 0)
    return (UNKNOWN_ENCODING, '') if text is None else (DEFINITION_ENCODING, text)


def type_description_hash(type_name: str) -> str:
    """Return the REP-2011 hash (``RIHS01_...``) of ``type_name``, or '' where none is installed."""
    split = _split(type_name)
    share = package_share(split[0]) if split else None
    if share is None:
        return ''
    try:
        described = json.loads((share / 'msg' / f'{split[1]}.json').read_text())
    except (OSError, ValueError):
        return ''
    qualified = f'{split[0]}/msg/{split[1]}'
    for entry in described.get('type_hashes', ()):
        if entry.get('type_name') == qualified:
            return str(entry.get('hash_string', ''))
    return ''


def _duration(nanoseconds: int) -> dict[str, int]:
    seconds, rest = divmod(nanoseconds, 1_000_000_000)
    return {'sec': seconds, 'nsec': rest}


def qos_profile(*, history: str = 'keep_last', depth: int = 10, reliability: str = 'reliable',
                durability: str = 'volatile', deadline_ns: int = 0, lifespan_ns: int = 0,
                liveliness: str = 'automatic', liveliness_lease_ns: int = 0,
                avoid_ros_namespace_conventions: bool = False) -> dict[str, Any]:
    """Return one QoS profile as rosbag2 (metadata version 9) writes it: policies as words.

    The words are rmw's (``keep_last``, ``reliable``, ``transient_local``,
    ...); durations are ``{sec, nsec}``, 0 meaning the rmw default.
    """
    return {
        'history': history, 'depth': depth, 'reliability': reliability,
        'durability': durability, 'deadline': _duration(deadline_ns),
        'lifespan': _duration(lifespan_ns), 'liveliness': liveliness,
        'liveliness_lease_duration': _duration(liveliness_lease_ns),
        'avoid_ros_namespace_conventions': avoid_ros_namespace_conventions,
    }


class _Topic:
    __slots__ = ('name', 'type', 'qos', 'hash', 'channel', 'count')

    def __init__(self, name: str, type_name: str, qos: Sequence[Mapping[str, Any]],
                 type_hash: str, channel: int) -> None:
        self.name = name
        self.type = type_name
        self.qos = [dict(profile) for profile in qos]
        self.hash = type_hash
        self.channel = channel
        self.count = 0


def _open_for_writing(path: pathlib.Path) -> IO[bytes]:
    """Open the MCAP file (the one place the writer touches the disk through)."""
    return open(path, 'xb')  # noqa: SIM115 -- closed by BagWriter.close


class BagWriter:
    """Writes one rosbag2 bag folder (MCAP storage); thread-safe.

    ``field`` names where the folder came from in error messages
    (``parameter 'record'``, ``--record``).  ``on_failure`` is called once,
    with one line, when writing fails and the recording stops.
    """

    def __init__(self, folder: str | os.PathLike, *, field: str,
                 on_failure: Callable[[str], None] | None = None) -> None:
        try:
            from mcap.writer import CompressionType, Writer
        except ImportError:
            raise ConfigurationError(f'{field}: {MCAP_HINT}') from None
        self.folder = pathlib.Path(folder)
        self._field = field
        self._on_failure = on_failure
        self._lock = threading.Lock()
        self._topics: dict[tuple[str, str], _Topic] = {}
        self._schemas: dict[str, int] = {}
        self._first_ns: int | None = None
        self._last_ns = 0
        self._count = 0
        self.failure: str | None = None
        self._closed = False
        if self.folder.exists():
            raise ConfigurationError(
                f"{field}: the bag folder '{self.folder}' already exists (give a new one)")
        self.file_name = f'{self.folder.name}_0.mcap'
        try:
            self.folder.mkdir(parents=True)
            self._stream = _open_for_writing(self.folder / self.file_name)
        except OSError as err:
            raise ConfigurationError(
                f"{field}: cannot write the bag folder '{self.folder}': "
                f'{one_line(err.strerror or str(err))}') from None
        try:
            self._writer = Writer(self._stream, chunk_size=CHUNK_SIZE,
                                  compression=CompressionType.NONE)
            self._writer.start(profile=PROFILE)
            self._stream.flush()
        except OSError as err:
            self.discard()
            raise ConfigurationError(
                f"{field}: cannot write the bag folder '{self.folder}': "
                f'{one_line(err.strerror or str(err))}') from None

    @property
    def recording(self) -> bool:
        """Whether messages are still being written (not closed, no write failed)."""
        return self.failure is None and not self._closed

    @property
    def message_count(self) -> int:
        """Messages written so far."""
        return self._count

    def add_topic(self, name: str, type_name: str,
                  qos: Sequence[Mapping[str, Any]]) -> tuple[str, str]:
        """Register topic ``name`` of ``type_name`` (once); return the key :meth:`write` takes.

        ``qos`` is the offered QoS, as :func:`qos_profile` gives it.
        """
        key = (name, type_name)
        with self._lock:
            if key in self._topics or not self.recording:
                return key
            try:
                schema = self._schemas.get(type_name)
                if schema is None:
                    encoding, text = message_definition(type_name)
                    schema = self._writer.register_schema(type_name, encoding, text.encode())
                    self._schemas[type_name] = schema
                type_hash = type_description_hash(type_name)
                channel = self._writer.register_channel(
                    name, SERIALIZATION_FORMAT, schema,
                    {'offered_qos_profiles': _yaml(list(qos)), 'topic_type_hash': type_hash})
            except OSError as err:
                self._fail(err)
                return key
            self._topics[key] = _Topic(name, type_name, qos, type_hash, channel)
        return key

    def write(self, key: tuple[str, str], data: bytes, time_ns: int) -> None:
        """Write one serialized message of topic ``key`` logged at ``time_ns``."""
        with self._lock:
            if self.failure is not None or self._closed:
                return
            topic = self._topics.get(key)
            if topic is None:
                return
            try:
                self._writer.add_message(topic.channel, time_ns, data, time_ns)
            except OSError as err:
                self._fail(err)
                return
            topic.count += 1
            self._count += 1
            if self._first_ns is None or time_ns < self._first_ns:
                self._first_ns = time_ns
            self._last_ns = max(self._last_ns, time_ns)

    def close(self) -> None:
        """Finish the MCAP file and write ``metadata.yaml`` (after a failure: only let go)."""
        with self._lock:
            if self._closed:
                return
            self._closed = True
            try:
                if self.failure is None:
                    self._writer.add_metadata('rosbag2', {
                        'serialized_metadata': _yaml(self._metadata())})
                    self._writer.finish()
                    self._stream.flush()
                    os.fsync(self._stream.fileno())
            except OSError as err:
                self._fail(err)
            finally:
                try:
                    self._stream.close()
                except OSError as err:
                    self._fail(err)
            if self.failure is None:
                try:
                    (self.folder / METADATA_FILE).write_text(
                        _yaml({'rosbag2_bagfile_information': self._metadata()}))
                except OSError as err:
                    self._fail(err)

    def discard(self) -> None:
        """Let go of the file and remove the folder this writer made (start-up failed)."""
        with self._lock:
            self._closed = True
            with contextlib.suppress(OSError):
                self._stream.close()
        with contextlib.suppress(OSError):
            for path in self.folder.iterdir():
                path.unlink(missing_ok=True)
            self.folder.rmdir()

    def _fail(self, err: OSError) -> None:
        """Stop recording after a write failed; say so once."""
        if self.failure is not None:
            return
        self.failure = one_line(err.strerror or str(err))
        if self._on_failure is not None:
            self._on_failure(
                f"{self._field}: stopped recording to '{self.folder}': {self.failure}; the "
                f'bag is cut short there (no index, no {METADATA_FILE})')

    def _metadata(self) -> dict[str, Any]:
        """rosbag2_storage's BagMetadata (version 9) of what was written so far."""
        start = self._first_ns or 0
        duration = self._last_ns - start if self._first_ns is not None else 0
        return {
            'version': METADATA_VERSION,
            'storage_identifier': STORAGE_IDENTIFIER,
            'duration': {'nanoseconds': duration},
            'starting_time': {'nanoseconds_since_epoch': start},
            'message_count': self._count,
            'topics_with_message_count': [
                {'topic_metadata': {
                    'name': topic.name, 'type': topic.type,
                    'serialization_format': SERIALIZATION_FORMAT,
                    'offered_qos_profiles': topic.qos,
                    'type_description_hash': topic.hash},
                 'message_count': topic.count}
                for topic in self._topics.values()],
            'compression_format': '',
            'compression_mode': '',
            'relative_file_paths': [self.file_name],
            'files': [{'path': self.file_name,
                       'starting_time': {'nanoseconds_since_epoch': start},
                       'duration': {'nanoseconds': duration},
                       'message_count': self._count}],
            'custom_data': {},
            'ros_distro': ROS_DISTRO,
        }


def _yaml(value: Any) -> str:
    return yaml.safe_dump(value, sort_keys=False, default_flow_style=False)
