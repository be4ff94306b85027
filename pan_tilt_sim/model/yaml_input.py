"""Reading a user's YAML with limits: nothing in it can crash, hang or exhaust memory.

Every YAML a user hands the package (controller files, world files, list
arguments) goes through here.  The limits:

* the file: a regular file (``/dev/zero``, a FIFO or a socket is refused
  before anything is read from it, so reading cannot block or never end) of
  at most :data:`MAX_FILE_BYTES`;
* the document: nested at most :data:`MAX_DEPTH` levels deep, counted after
  aliases are expanded, and at most :data:`MAX_EXPANDED_NODES` values once
  every alias is expanded (so a "billion laughs" file of nested aliases is
  refused instead of being walked);
* an alias that refers to its own anchor (``a: &a [*a]``) is refused: the
  data would contain itself.

Design notes: docs/design/model.md#yaml_inputpy.
"""

from __future__ import annotations

import os
import pathlib
import stat
from typing import Any

import yaml
from yaml.composer import Composer
from yaml.constructor import SafeConstructor
from yaml.resolver import Resolver

try:
    from yaml.cyaml import CParser as _SyntaxParser
    _C_SYNTAX = True
except ImportError:  # PyYAML built without libyaml
    _C_SYNTAX = False

MAX_FILE_BYTES = 1 << 20  # 1 MiB: controller and world files are a few kilobytes
MAX_DEPTH = 64  # levels of nesting, aliases expanded; controller files use under 10
# Values (scalars, sequences, mappings) once every alias is expanded.  A file of
# MAX_FILE_BYTES without aliases holds fewer than this, so only aliases reach it.
MAX_EXPANDED_NODES = 1_000_000

_FILE_KINDS = (
    (stat.S_ISCHR, 'a character device'),
    (stat.S_ISBLK, 'a block device'),
    (stat.S_ISFIFO, 'a FIFO'),
    (stat.S_ISSOCK, 'a socket'),
)


class YamlInputError(Exception):
    """What is wrong with a YAML input, in one line, without the input's name.

    ``line`` is the 1-based line the problem is at, when it has one.
    """

    def __init__(self, problem: str, line: int | None = None) -> None:
        super().__init__(problem)
        self.problem = problem
        self.line = line

    @property
    def where(self) -> str:
        """``':<line>'`` to put after the file's name, or ''."""
        return f':{self.line}' if self.line is not None else ''


def read_text(path: pathlib.Path, max_bytes: int = MAX_FILE_BYTES) -> str:
    """Return the UTF-8 text of the regular file ``path``, of at most ``max_bytes`` bytes.

    Raises :class:`YamlInputError`: no such file, a directory, not a regular
    file (a device, FIFO or socket: refused without reading, so it cannot
    block), larger than ``max_bytes``, or unreadable (permissions, not UTF-8).
    """
    try:
        # Non-blocking, so that opening a FIFO returns at once; it is refused below.
        descriptor = os.open(path, os.O_RDONLY | os.O_NONBLOCK)
    except FileNotFoundError:
        raise YamlInputError('no such file') from None
    except IsADirectoryError:
        raise YamlInputError('is a directory, not a file') from None
    except OSError as err:
        raise YamlInputError(f'cannot read: {err.strerror or err}') from None
    mode = os.fstat(descriptor).st_mode
    if not stat.S_ISREG(mode):
        os.close(descriptor)
        if stat.S_ISDIR(mode):
            raise YamlInputError('is a directory, not a file')
        kind = next((name for test, name in _FILE_KINDS if test(mode)), 'not a file')
        raise YamlInputError(f'not a regular file ({kind})')
    with os.fdopen(descriptor, 'rb') as stream:
        try:
            data = stream.read(max_bytes + 1)
        except OSError as err:
            raise YamlInputError(f'cannot read: {err.strerror or err}') from None
    if len(data) > max_bytes:
        raise YamlInputError(
            f'larger than {max_bytes} bytes ({max_bytes // 1024} KiB), the most a YAML file '
            'may have here')
    try:
        return data.decode('utf-8')
    except UnicodeDecodeError as err:
        raise YamlInputError(f'cannot read: not UTF-8 text ({err.reason} at byte '
                             f'{err.start})') from None


class _BoundedComposer(Composer):
    """PyYAML's composer, refusing nesting deeper than :data:`MAX_DEPTH` as it composes."""

    def __init__(self) -> None:
        super().__init__()
        self._depth = 0

    def compose_node(self, parent: yaml.Node | None, index: Any) -> yaml.Node:
        """Compose one node, one level deeper than ``parent``."""
        self._depth += 1
        try:
            if self._depth > MAX_DEPTH:
                mark = self.peek_event().start_mark
                raise YamlInputError(f'nested deeper than {MAX_DEPTH} levels',
                                     mark.line + 1 if mark is not None else None)
            return super().compose_node(parent, index)
        finally:
            self._depth -= 1


if _C_SYNTAX:
    class _Loader(_BoundedComposer, _SyntaxParser, SafeConstructor, Resolver):
        """libyaml's events, the bounded composer, PyYAML's safe constructor."""

        def __init__(self, stream: str) -> None:
            _SyntaxParser.__init__(self, stream)
            SafeConstructor.__init__(self)
            Resolver.__init__(self)
            _BoundedComposer.__init__(self)
else:  # pragma: no cover - PyYAML wheels ship libyaml
    from yaml.parser import Parser
    from yaml.reader import Reader
    from yaml.scanner import Scanner

    class _Loader(_BoundedComposer, Reader, Scanner, Parser,  # type: ignore[no-redef]
                  SafeConstructor, Resolver):
        """PyYAML's Python parser, the bounded composer, PyYAML's safe constructor."""

        def __init__(self, stream: str) -> None:
            Reader.__init__(self, stream)
            Scanner.__init__(self)
            Parser.__init__(self)
            SafeConstructor.__init__(self)
            Resolver.__init__(self)
            _BoundedComposer.__init__(self)


def _children(node: yaml.Node) -> list[yaml.Node]:
    if isinstance(node, yaml.SequenceNode):
        return list(node.value)
    if isinstance(node, yaml.MappingNode):
        return [item for pair in node.value for item in pair]
    return []


def _line(node: yaml.Node) -> int | None:
    mark = node.start_mark
    return mark.line + 1 if mark is not None else None


def check_expansion(root: yaml.Node) -> None:
    """Refuse a node graph that aliases make cyclic, too deep or too large.

    Walks the graph once (each shared node's size and height are kept), without
    recursion.  Raises :class:`YamlInputError`.
    """
    sizes: dict[int, int] = {}
    heights: dict[int, int] = {}
    on_path: set[int] = set()
    stack: list[tuple[yaml.Node, bool]] = [(root, False)]
    while stack:
        node, finished = stack.pop()
        key = id(node)
        if finished:
            children = _children(node)
            size = 1 + sum(sizes[id(child)] for child in children)
            height = 1 + max((heights[id(child)] for child in children), default=0)
            on_path.discard(key)
            if height > MAX_DEPTH:
                raise YamlInputError(
                    f'nested deeper than {MAX_DEPTH} levels once its aliases are expanded',
                    _line(node))
            if size > MAX_EXPANDED_NODES:
                raise YamlInputError(
                    f'its aliases expand it to more than {MAX_EXPANDED_NODES:,} values '
                    '(aliases of aliases multiply)', _line(node))
            sizes[key], heights[key] = size, height
            continue
        if key in sizes:
            continue
        if key in on_path:
            raise YamlInputError(
                'an alias refers to the node that holds it (its anchor), so the data would '
                'contain itself', _line(node))
        on_path.add(key)
        stack.append((node, True))
        stack.extend((child, False) for child in _children(node) if id(child) not in sizes)


def compose(text: str) -> yaml.Node | None:
    """Return the node graph of the one YAML document in ``text`` (None if empty), checked.

    Raises :class:`YamlInputError` for a syntax error (with its line), more
    than one document, or a graph over the limits (:func:`check_expansion`).
    """
    loader = _Loader(text)
    try:
        node = _compose(loader)
    finally:
        loader.dispose()
    if node is not None:
        check_expansion(node)
    return node


def _compose(loader: _Loader) -> yaml.Node | None:
    try:
        return loader.get_single_node()
    except yaml.MarkedYAMLError as err:
        mark = err.problem_mark or err.context_mark
        problem = err.problem or err.context or 'invalid YAML'
        raise YamlInputError(f'YAML syntax error: {problem}',
                             mark.line + 1 if mark is not None else None) from None
    except yaml.YAMLError as err:
        raise YamlInputError(f'YAML error: {err}') from None


def load(text: str) -> Any:
    """Return the data of the one YAML document in ``text`` (None if empty), within the limits.

    As ``yaml.safe_load``, but the document is checked (:func:`compose`)
    before it is constructed.  Aliases stay shared objects, as PyYAML makes
    them.  Raises :class:`YamlInputError`.
    """
    loader = _Loader(text)
    try:
        node = _compose(loader)
        if node is None:
            return None
        check_expansion(node)
        try:
            return loader.construct_document(node)
        except yaml.MarkedYAMLError as err:
            mark = err.problem_mark or err.context_mark
            raise YamlInputError(f'YAML error: {err.problem or err.context}',
                                 mark.line + 1 if mark is not None else None) from None
        except yaml.YAMLError as err:
            raise YamlInputError(f'YAML error: {err}') from None
    finally:
        loader.dispose()


def load_file(path: pathlib.Path, max_bytes: int = MAX_FILE_BYTES) -> Any:
    """Return the data of the YAML file ``path`` (:func:`read_text`, then :func:`load`)."""
    return load(read_text(path, max_bytes))
