"""Reading bags back with independent readers, and a disk that fills up."""

from __future__ import annotations

import errno
import pathlib

from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory

NANOSECONDS_PER_SECOND = 1_000_000_000


def read(folder: pathlib.Path) -> dict:
    """Return the bag's MCAP header, schemas, channels, metadata records and decoded messages."""
    (mcap_file,) = folder.glob('*.mcap')
    with mcap_file.open('rb') as stream:
        reader = make_reader(stream, decoder_factories=[DecoderFactory()])
        header = reader.get_header()
        summary = reader.get_summary()
        messages = [(channel.topic, message.log_time, decoded)
                    for _schema, channel, message, decoded
                    in reader.iter_decoded_messages(log_time_order=True)]
        metadata = {record.name: record.metadata for record in reader.iter_metadata()}
    return {'header': header, 'schemas': summary.schemas, 'channels': summary.channels,
            'statistics': summary.statistics, 'messages': messages, 'metadata': metadata}


def read_with_rosbags(folder: pathlib.Path) -> dict:
    """Open the bag with rosbags' rosbag2 reader (metadata.yaml first, as rosbag2 does).

    Every message is decoded with the types the bag's own definitions declare;
    returns the reader's topic counts, duration, start and the decoded messages.
    """
    from rosbags.rosbag2 import Reader
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    with Reader(folder) as reader:
        store = get_typestore(Stores.EMPTY)
        types = {}
        for connection in reader.connections:
            types.update(get_types_from_msg(connection.msgdef.data, connection.msgtype))
        store.register(types)
        messages = [(connection.topic, time, store.deserialize_cdr(raw, connection.msgtype))
                    for connection, time, raw in reader.messages()]
        counts = {connection.topic: connection.msgcount for connection in reader.connections}
        return {'counts': counts, 'duration': reader.duration, 'start': reader.start_time,
                'messages': messages}


def topic_messages(content: dict, topic: str) -> list[tuple[int, object]]:
    """Return (log time in ns, decoded message) of every message on ``topic``, in time order."""
    return [(time, decoded) for name, time, decoded in content['messages'] if name == topic]


class FullDisk:
    """A file that takes ``room`` bytes, then fails as a full disk does."""

    def __init__(self, path: pathlib.Path, room: int) -> None:
        self._file = open(path, 'xb')  # noqa: SIM115 -- closed by close()
        self.room = room

    def write(self, data: bytes) -> int:
        if len(data) > self.room:
            raise OSError(errno.ENOSPC, 'No space left on device')
        self.room -= len(data)
        return self._file.write(data)

    def __getattr__(self, name: str):
        return getattr(self._file, name)
