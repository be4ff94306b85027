"""Reading a user's YAML with limits: every hostile input is one error, quickly, never a crash."""

import os

import pytest
import yaml

from pan_tilt_sim.model import yaml_input
from pan_tilt_sim.model.yaml_input import (
    MAX_DEPTH,
    MAX_EXPANDED_NODES,
    MAX_FILE_BYTES,
    YamlInputError,
)


def billion_laughs(levels: int = 9, fan_out: int = 9) -> str:
    """Each level a list of ``fan_out`` aliases of the level below: fan_out**levels values."""
    lines = [f"a0: &a0 [{', '.join(['lol'] * fan_out)}]"]
    for level in range(1, levels + 1):
        lines.append(f"a{level}: &a{level} [{', '.join([f'*a{level - 1}'] * fan_out)}]")
    return '\n'.join(lines) + '\n'


def nested_flow(depth: int) -> str:
    return '[' * depth + ']' * depth


def nested_block(depth: int) -> str:
    return ''.join(f"{'  ' * level}k{level}:\n" for level in range(depth)) + '  ' * depth + 'x\n'


@pytest.mark.parametrize('text', [
    'a: &a [*a]\n',
    'a: &a {b: *a}\n',
    'a: &a {<<: *a}\n',
    'a: &a [[[*a]]]\n',
], ids=['list', 'mapping', 'merge key', 'three levels down'])
def test_an_alias_inside_its_own_anchor_is_refused(text):
    with pytest.raises(YamlInputError, match='alias refers to the node that holds it') as raised:
        yaml_input.load(text)
    assert raised.value.line == 1


@pytest.mark.parametrize('text', [nested_flow(500), nested_block(500), nested_flow(100_000)],
                         ids=['500 flow levels', '500 block levels', '100,000 flow levels'])
def test_nesting_deeper_than_the_bound_is_refused_without_recursion_error(text):
    # libyaml refuses the deepest itself (its own limit), the composer the others.
    with pytest.raises(YamlInputError,
                       match=f'nested deeper than {MAX_DEPTH} levels|maximum nesting depth'):
        yaml_input.load(text)


def test_nesting_at_the_bound_loads():
    assert yaml_input.load(nested_flow(MAX_DEPTH)) is not None
    with pytest.raises(YamlInputError):
        yaml_input.load(nested_flow(MAX_DEPTH + 1))


def test_depth_reached_through_aliases_is_bounded_too():
    # Each anchor is shallow as written; expanded, they stack up past the bound.
    half = MAX_DEPTH // 2
    text = f'a: &a {nested_flow(half)}\nb: &b {nested_flow(half)[:half]}*a{"]" * half}\n'
    text += f'c: {nested_flow(half)[:half]}*b{"]" * half}\n'
    with pytest.raises(YamlInputError, match='once its aliases are expanded'):
        yaml_input.load(text)


def test_a_billion_laughs_is_refused_at_once():
    with pytest.raises(YamlInputError, match='aliases expand it to more than') as raised:
        yaml_input.load(billion_laughs())
    assert raised.value.line is not None


def test_aliases_expanding_within_the_bound_load_as_shared_objects():
    # 6 levels of 9: 531,441 leaves, under the bound.
    data = yaml_input.load(billion_laughs(levels=5))
    assert data['a5'][0] is data['a4']
    assert 9 ** 6 < MAX_EXPANDED_NODES


def test_ordinary_yaml_loads_as_safe_load_reads_it():
    text = ('defaults: &defaults {p: 1.0, i: 0.01}\n'
            'pan: {<<: *defaults, d: 10}\n'
            'list: [1, 2.5, true, null, "s"]\n'
            'stamp: 2001-12-14\n')
    assert yaml_input.load(text) == yaml.safe_load(text)


@pytest.mark.parametrize(('text', 'problem', 'line'), [
    ('a:\n  type: [unclosed\n  joint: pan_joint\n', 'YAML syntax error', 3),
    ('a: 1\n---\nb: 2\n', 'YAML syntax error', 2),
    ('a: !!python/object:os.system x\n', 'YAML error', 1),
], ids=['unclosed list', 'two documents', 'unsafe tag'])
def test_syntax_errors_say_what_and_where(text, problem, line):
    with pytest.raises(YamlInputError, match=problem) as raised:
        yaml_input.load(text)
    assert raised.value.line == line
    assert '\n' not in str(raised.value)


def test_an_empty_document_is_none():
    assert yaml_input.load('') is None
    assert yaml_input.compose('# nothing\n') is None


def test_compose_applies_the_same_limits():
    with pytest.raises(YamlInputError, match='alias refers'):
        yaml_input.compose('a: &a [*a]\n')
    with pytest.raises(YamlInputError, match='expand it to more than'):
        yaml_input.compose(billion_laughs())


# --- files ----------------------------------------------------------------------------------

@pytest.mark.parametrize('device', ['/dev/null', '/dev/zero'])
def test_a_device_is_not_a_regular_file(device):
    with pytest.raises(YamlInputError, match=r'not a regular file \(a character device\)'):
        yaml_input.read_text(device)


def test_a_fifo_is_refused_without_blocking(tmp_path):
    fifo = tmp_path / 'controllers.yaml'
    os.mkfifo(fifo)
    with pytest.raises(YamlInputError, match=r'not a regular file \(a FIFO\)'):
        yaml_input.read_text(fifo)


def test_a_missing_file_and_a_folder_say_so(tmp_path):
    with pytest.raises(YamlInputError, match='no such file'):
        yaml_input.read_text(tmp_path / 'missing.yaml')
    with pytest.raises(YamlInputError, match='is a directory'):
        yaml_input.read_text(tmp_path)


def test_a_file_over_the_size_bound_is_refused_before_parsing(tmp_path):
    at_bound = tmp_path / 'at.yaml'
    at_bound.write_bytes(b'#' * (MAX_FILE_BYTES - 1) + b'\n')
    assert yaml_input.load_file(at_bound) is None
    over = tmp_path / 'over.yaml'
    over.write_bytes(b'a: 1\n' * (16 * 1024 * 1024 // 5))
    with pytest.raises(YamlInputError, match=f'larger than {MAX_FILE_BYTES} bytes'):
        yaml_input.read_text(over)


def test_bytes_that_are_not_utf8_are_refused(tmp_path):
    path = tmp_path / 'binary.yaml'
    path.write_bytes(b'a: \xff\xfe\n')
    with pytest.raises(YamlInputError, match='not UTF-8'):
        yaml_input.load_file(path)
