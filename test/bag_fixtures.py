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
