"""Command-line flags read as gflags reads them (ros_gz_sim's ``create`` uses gflags).

``-name value``, ``--name value``, ``-name=value``; a bool flag alone is true
(``-flag=false`` sets it false, ``-noflag`` too) and never takes the next word, so in
``-allow_renaming true`` the ``true`` is a leftover word, as with gflags.  A flag
that takes a value takes the next word whatever it is (``-x -2.0``).  ``--`` ends the
flags.  An unknown flag, a missing value or a value of the wrong type is a
:class:`FlagError` with gflags' wording.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

TRUE_WORDS = ('true', 't', 'yes', 'y', '1')
FALSE_WORDS = ('false', 'f', 'no', 'n', '0')


class FlagError(ValueError):
    """A command line gflags would refuse: the message is gflags' ERROR line."""


def parse_flags(argv: Sequence[str], defaults: Mapping[str, Any]
                ) -> tuple[dict[str, Any], list[str], set[str]]:
    """Return (values, leftover words, names given) of ``argv`` (no program name).

    ``defaults`` gives each flag's name and type (bool, float, str) through its value.
    """
    values = dict(defaults)
    given: set[str] = set()
    leftover: list[str] = []
    words = list(argv)
    index = 0
    while index < len(words):
        word = words[index]
        index += 1
        if word == '--':
            leftover += words[index:]
            break
        if not word.startswith('-') or word == '-':
            leftover.append(word)
            continue
        name, has_value, value = word.lstrip('-').partition('=')
        if name not in values and name.startswith('no') and isinstance(
                values.get(name[2:]), bool) and not has_value:
            values[name[2:]] = False
            given.add(name[2:])
            continue
        if name not in values:
            raise FlagError(f"ERROR: unknown command line flag '{name}'")
        default = values[name]
        if isinstance(default, bool):
            if has_value:
                values[name] = _bool(name, value)
            else:
                values[name] = True
            given.add(name)
            continue
        if not has_value:
            if index >= len(words):
                raise FlagError(f"ERROR: flag '{word}' is missing its argument")
            value = words[index]
            index += 1
        values[name] = _typed(name, default, value)
        given.add(name)
    return values, leftover, given


def _bool(name: str, value: str) -> bool:
    if value.lower() in TRUE_WORDS:
        return True
    if value.lower() in FALSE_WORDS:
        return False
    raise FlagError(f"ERROR: illegal value '{value}' specified for bool flag '{name}'")


def _typed(name: str, default: Any, value: str) -> Any:
    if isinstance(default, float):
        try:
            return float(value)
        except ValueError:
            raise FlagError(
                f"ERROR: illegal value '{value}' specified for double flag '{name}'") from None
    return value
