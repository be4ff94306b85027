"""Command-line flags read as gflags reads them (ros_gz_sim's ``create`` uses gflags).

``-name value``, ``--name value``, ``-name=value``; a bool flag alone is true
(``-flag=false`` sets it false, ``-noflag`` too) and never takes the next word, so in
``-allow_renaming true`` the ``true`` is a leftover word, as with gflags.  A flag
that takes a value takes the next word whatever it is (``-x -2.0``).  ``--`` ends the
flags.  gflags' own flags: ``--flagfile`` (one flag a line), ``--fromenv`` and
``--tryfromenv`` (``FLAGS_<name>`` variables), ``--undefok`` (unknown flags it names
pass, taking no value); ``--help*`` and ``--version`` are a :class:`FlagExitError`.  An
unknown flag, a missing value or a value of the wrong type is a :class:`FlagError`
with gflags' wording.
"""

from __future__ import annotations

import os
import pathlib
from collections.abc import Mapping, Sequence
from typing import Any

TRUE_WORDS = ('true', 't', 'yes', 'y', '1')
FALSE_WORDS = ('false', 'f', 'no', 'n', '0')
# gflags' own flags that end the program: the exit code gflags gives each.
HELP_FLAGS = {'help': 1, 'helpfull': 1, 'helpshort': 1, 'helpxml': 1, 'helpon': 1,
              'helpmatch': 1, 'helppackage': 1, 'version': 0}
# gflags' own flags that take a value (a path, or a comma-separated list of flag names).
OWN_FLAGS = ('flagfile', 'fromenv', 'tryfromenv', 'undefok')


class FlagError(ValueError):
    """A command line gflags would refuse: the message is gflags' ERROR line."""


class FlagExitError(Exception):
    """``--help*`` or ``--version``: the program prints its usage and ends with ``code``."""

    def __init__(self, flag: str, code: int) -> None:
        super().__init__(flag)
        self.flag, self.code = flag, code


def parse_flags(argv: Sequence[str], defaults: Mapping[str, Any],
                environ: Mapping[str, str] | None = None
                ) -> tuple[dict[str, Any], list[str], set[str]]:
    """Return (values, leftover words, names given) of ``argv`` (no program name).

    ``defaults`` gives each flag's name and type (bool, float, str) through its value;
    ``environ`` (default the process's) is what ``--fromenv`` reads.
    """
    environ = os.environ if environ is None else environ
    values = dict(defaults)
    given: set[str] = set()
    leftover: list[str] = []
    unknown: list[str] = []
    undefok: set[str] = set()
    ending: FlagExitError | None = None
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
        if name in HELP_FLAGS:
            if name in ('helpon', 'helpmatch') and not has_value:
                index += 1  # a module name: what to list
            ending = ending or FlagExitError(name, HELP_FLAGS[name])
            continue
        if name in OWN_FLAGS:
            if not has_value:
                if index >= len(words):
                    raise FlagError(f"ERROR: flag '{word}' is missing its argument")
                value, index = words[index], index + 1
            if name == 'flagfile':
                words[index:index] = _flagfile(value)
            elif name == 'undefok':
                undefok.update(part for part in value.split(',') if part)
            else:
                words[index:index] = _from_environment(value, environ, name == 'fromenv')
            continue
        if name not in values:
            unknown.append(name)  # an error unless --undefok names it (read at the end)
            continue
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
    for name in unknown:
        if name not in undefok and not (name.startswith('no') and name[2:] in undefok):
            raise FlagError(f"ERROR: unknown command line flag '{name}'")
    if ending is not None:
        raise ending
    return values, leftover, given


def _flagfile(path: str) -> list[str]:
    """Return the flags of a gflags flagfile: one a line (blank lines, ``#`` comments skipped)."""
    try:
        lines = pathlib.Path(path).expanduser().read_text().splitlines()
    except OSError as err:
        raise FlagError(f"ERROR: could not read flagfile '{path}': {err.strerror}") from None
    return [line.strip() for line in lines if line.strip().startswith('-')]


def _from_environment(names: str, environ: Mapping[str, str], required: bool) -> list[str]:
    """``--name=value`` words of the ``FLAGS_<name>`` variables (``--fromenv``: all required)."""
    words = []
    for name in (part for part in names.split(',') if part):
        if f'FLAGS_{name}' in environ:
            words.append(f"--{name}={environ[f'FLAGS_{name}']}")
        elif required:
            raise FlagError(f'ERROR: FLAGS_{name} not found in environment')
    return words


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
