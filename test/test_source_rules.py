"""Rules the package's source keeps: a module opens with a short docstring.

A module docstring says what the module is for, its contracts, units and reasons, in at most
20 lines; the design essays live in docs/architecture.md and docs/design/.  The check walks
every ``*.py`` under ``pan_tilt_sim/``, so modules in new folders are covered the day they land.
"""

from __future__ import annotations

import ast
import pathlib

REPO = pathlib.Path(__file__).resolve().parents[1]
PACKAGE = REPO / 'pan_tilt_sim'
MAX_MODULE_DOCSTRING_LINES = 20


def long_module_docstrings(root: pathlib.Path, limit: int) -> list[str]:
    """Return ``path: N lines`` for each module under ``root`` whose docstring exceeds ``limit``.

    A docstring's lines are those of its string literal, the quotes' lines included.
    """
    found = []
    for path in sorted(root.rglob('*.py')):
        body = ast.parse(path.read_text(encoding='utf-8'), filename=str(path)).body
        if not body or ast.get_docstring(ast.Module(body=body[:1], type_ignores=[])) is None:
            continue
        lines = body[0].end_lineno - body[0].lineno + 1
        if lines > limit:
            found.append(f'{path.relative_to(root.parent)}: {lines} lines')
    return found


def test_no_module_docstring_is_over_20_lines():
    long = long_module_docstrings(PACKAGE, MAX_MODULE_DOCSTRING_LINES)
    assert not long, (
        f'module docstrings over {MAX_MODULE_DOCSTRING_LINES} lines (keep what the module '
        'promises; move the design to docs/design/):\n' + '\n'.join(long))


def test_the_walk_reaches_every_folder_of_the_package():
    folders = {path.parent for path in PACKAGE.rglob('*.py')}
    assert {PACKAGE / 'model', PACKAGE / 'controllers', PACKAGE / 'sim', PACKAGE / 'ros',
            PACKAGE / 'tools'} <= folders


def test_a_long_docstring_in_a_new_folder_is_named_with_its_length(tmp_path):
    package = tmp_path / 'pkg'
    (package / 'family' / 'deeper').mkdir(parents=True)
    body = '\n'.join(f'line {n}' for n in range(19))
    (package / 'family' / 'deeper' / 'long.py').write_text(f'"""{body}\n"""\nX = 1\n')
    (package / 'family' / 'short.py').write_text(f'"""{body}"""\n')
    (package / 'family' / 'none.py').write_text('X = """not a docstring\n\n\n"""\n')
    assert long_module_docstrings(package, 19) == ['pkg/family/deeper/long.py: 20 lines']
