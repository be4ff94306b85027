"""The README and docs/ hold: no run history, links that resolve, and commands that work.

* No line of the docs, the package or the tests names a benchmark run ("run Q"), an issue
  number or the machine something was measured on: figures belong in docs/performance.md,
  comments state contracts and reasons.
* Every relative link of README.md and docs/*.md names a file that exists and, with an
  ``#anchor``, a heading of that file.
* Every command of their fenced ``bash`` blocks is either run here (the examples against a
  sim_node process, ``step_response``, ``build_interfaces.sh --status``, the controller
  reference) or checked against the code: each ``-p name:=value`` is a sim_node parameter and
  the setup it describes starts; each ``ros2 topic pub``/``echo`` names a topic of the type
  sim_node creates for that setup, with data that fills the message; each console script and
  option exists.  A command nothing here knows how to check fails the test, so a new kind of
  command in the docs comes with its check.
"""

from __future__ import annotations

import dataclasses
import functools
import importlib
import os
import pathlib
import re
import shlex
import subprocess
import sys
import tempfile
from collections.abc import Iterator

import pytest
import sim_process
import yaml
from node_harness import sim_node

from pan_tilt_sim.controllers.framework.registry import CONTROLLER_CLASSES
from pan_tilt_sim.controllers.framework.surface import ActionServer, CommandTopic, StateTopic
from pan_tilt_sim.ros.sim_node import NODE_NAME
from pan_tilt_sim.share import package_share
from pan_tilt_sim.tools.controller_reference import example_controller

REPO = pathlib.Path(__file__).resolve().parents[1]
THIS_FILE = pathlib.Path(__file__).resolve()
DOCS = (REPO / 'README.md', *sorted((REPO / 'docs').rglob('*.md')))
PACKAGE = 'pan_tilt_sim'


def doc_id(path: pathlib.Path) -> str:
    """A doc's test id: its name, or its path under docs/ (docs/design/ reuses names)."""
    return str(path.relative_to(REPO / 'docs')) if REPO / 'docs' in path.parents else path.name

BIN = pathlib.Path(sys.executable).parent
RUN_BUDGET_S = 90.0
STOP_BUDGET_S = 10.0

# --- no run history, issue numbers or machine notes ---------------------------------------------

HISTORY = re.compile(
    r'(?<![\w-])[Rr]uns? [A-Z](?:\+[A-Z])*(?![\w′])'  # "run Q", "runs N and O", "run S+T+U"
    r'|\b[Ii]ssues? #?\d+'                      # "issue 16"
    r'|\bthese VMs\b|\bthis VM\b|\bon this machine\b')
SCANNED_SUFFIXES = {'.py', '.c', '.md', '.sh'}


def history_notes(paths: list[pathlib.Path], root: pathlib.Path) -> list[str]:
    """Return ``file:line: text`` for each line naming a run, an issue or the machine."""
    found = []
    for path in paths:
        for number, line in enumerate(path.read_text(encoding='utf-8').splitlines(), start=1):
            if HISTORY.search(line):
                found.append(f'{path.relative_to(root)}:{number}: {line.strip()}')
    return found


def scanned_files() -> list[pathlib.Path]:
    """README.md, docs/, the package, the tests and the scripts, this file aside."""
    files = [REPO / 'README.md', *(REPO / 'docs').rglob('*.md')]
    for folder in ('pan_tilt_sim', 'test', 'scripts'):
        files += [path for path in (REPO / folder).rglob('*')
                  if path.suffix in SCANNED_SUFFIXES and path.is_file()]
    return sorted(path for path in files if path.resolve() != THIS_FILE)


def test_no_doc_comment_or_test_names_a_run_an_issue_or_the_machine():
    notes = history_notes(scanned_files(), REPO)
    assert not notes, 'history belongs in no file; figures in docs/performance.md:\n' + \
        '\n'.join(notes)


@pytest.mark.parametrize('line', ['# 4.1 us, measured in run Q', 'the best of runs N and O',
                                  'Run S+T+U is the table', 'before issue 16 made it flatter',
                                  '(slower on these VMs)', 'as measured on this machine'])
def test_the_scan_names_the_file_and_line_of_a_history_note(tmp_path, line):
    planted = tmp_path / 'module.py'
    planted.write_text(f'"""A module."""\n{line}\n')
    assert history_notes([planted], tmp_path) == [f'module.py:2: {line}']


@pytest.mark.parametrize('line', ['steps run in C', 'a run of 15 s', 'runs the PIDs in C',
                                  'issue a warning', 'on the local machine',
                                  '``--runs N`` repeats it'])
def test_the_scan_leaves_ordinary_words_alone(tmp_path, line):
    planted = tmp_path / 'module.py'
    planted.write_text(line + '\n')
    assert history_notes([planted], tmp_path) == []


# --- links ------------------------------------------------------------------------------------

FENCE = re.compile(r'^\s*```')
LINK = re.compile(r'\]\(([^)\s]+)\)')


def github_anchor(heading: str) -> str:
    """The anchor GitHub gives a heading: lower case, punctuation dropped, spaces as hyphens."""
    return re.sub(r'[^\w\- ]', '', heading.strip().lower()).replace(' ', '-')


def headings(path: pathlib.Path) -> set[str]:
    """The anchors of a Markdown file's headings (fenced code aside)."""
    anchors, fenced = set(), False
    for line in path.read_text(encoding='utf-8').splitlines():
        if FENCE.match(line):
            fenced = not fenced
        elif not fenced and line.startswith('#'):
            anchors.add(github_anchor(line.lstrip('#')))
    return anchors


def broken_links(path: pathlib.Path) -> list[str]:
    """Return each relative link of ``path`` whose file or heading does not exist."""
    broken = []
    for number, line in enumerate(path.read_text(encoding='utf-8').splitlines(), start=1):
        for target in LINK.findall(line):
            if re.match(r'[a-z]+://', target):
                continue
            name, _, anchor = target.partition('#')
            destination = (path.parent / name) if name else path
            where = f'{path.relative_to(REPO)}:{number}: {target}'
            if not destination.exists():
                broken.append(f'{where} (no such file)')
            elif anchor and destination.suffix == '.md' and anchor not in headings(destination):
                broken.append(f'{where} (no such heading)')
    return broken


@pytest.mark.parametrize('doc', DOCS, ids=doc_id)
def test_every_relative_link_names_a_file_and_heading_that_exist(doc):
    assert broken_links(doc) == []


def test_a_link_to_a_missing_heading_is_reported(tmp_path, monkeypatch):
    monkeypatch.setattr(sys.modules[__name__], 'REPO', tmp_path)
    (tmp_path / 'a.md').write_text('# Title\n\n## Where is it?\n\n[x](b.md) [y](#where-is-it) '
                                   '[z](#nowhere)\n')
    assert broken_links(tmp_path / 'a.md') == ['a.md:5: b.md (no such file)',
                                               'a.md:5: #nowhere (no such heading)']


# --- the commands -----------------------------------------------------------------------------

PREFIX = re.compile(r'\$\(ros2 pkg prefix ([\w-]+)\)')
ENVIRONMENT = re.compile(r'^[A-Z_][A-Z0-9_]*=')
SEPARATORS = {'&&', ';', '||', '|'}
GENERAL_TOOLS = {'mkdir', 'cd', 'git', 'source', 'ray'}  # nothing of this package in them
PLACEHOLDER = '/path/to/'
# A documented record:=<folder> records into a fresh folder here, not the checkout.
_BAGS = tempfile.TemporaryDirectory(prefix='pan_tilt_docs_bags_')


@dataclasses.dataclass(frozen=True)
class Command:
    """One command line of a fenced bash block: where it is, its environment and its words."""

    doc: str
    line: int
    environment: tuple[tuple[str, str], ...]
    words: tuple[str, ...]

    @property
    def where(self) -> str:
        """``file:line`` of the command in the docs."""
        return f'{self.doc}:{self.line}'


def _split(text: str) -> list[str]:
    return shlex.split(PREFIX.sub(r'@prefix:\1@', text), comments=True)


def commands(path: pathlib.Path) -> Iterator[Command]:
    """Yield the commands of ``path``'s fenced bash blocks, continuation lines joined."""
    lines = path.read_text(encoding='utf-8').splitlines()
    block, buffer, start = False, '', 0
    variables: dict[str, str] = {}  # shell variables the doc sets (NAME=value alone on a line)
    for number, line in enumerate(lines, start=1):
        if FENCE.match(line):
            block = line.strip() == '```bash' if not block else False
            continue
        if not block:
            continue
        if not buffer:
            start = number
        buffer = f'{buffer}\n{line}' if buffer else line
        if buffer.endswith('\\'):
            buffer = buffer[:-1]
            continue
        try:
            words = _split(buffer)
        except ValueError:  # a quoted argument goes on on the next line
            continue
        buffer = ''
        part: list[str] = []
        for word in [*words, ';']:
            if word not in SEPARATORS:
                part.append(word)
                continue
            part = [re.sub(r'\$\{?(\w+)\}?', lambda match: variables.get(match[1], match[0]),
                           word) for word in part]
            environment = []
            while part and ENVIRONMENT.match(part[0]):
                name, _, value = part.pop(0).partition('=')
                environment.append((name, value))
            if part:
                yield Command(str(path.relative_to(REPO)), start, tuple(environment), tuple(part))
            else:
                variables.update(environment)
            part = []


ALL_COMMANDS = [command for doc in DOCS for command in commands(doc)]


def test_the_docs_have_commands_to_check():
    # Guards the parser: the README's quick start alone has two.
    assert {'scripts/run_sim.sh', 'scripts/run_tests.sh'} <= {c.words[0] for c in ALL_COMMANDS}
    multi_line = [c for c in ALL_COMMANDS if c.words[:3] == ('ros2', 'topic', 'pub')
                  and 'joint_names' in c.words[-1]]
    assert multi_line, 'the multi-line trajectory commands were not joined'


def executables() -> dict[str, str]:
    """The package's executables, from setup.py (what ``ros2 run pan_tilt_sim`` finds)."""
    text = (REPO / 'setup.py').read_text(encoding='utf-8')
    table = re.search(r'EXECUTABLES = \{(.*?)\}', text, re.S).group(1)
    return dict(re.findall(r"'(\w+)': '([\w.:]+)'", table))


@functools.lru_cache
def help_text(executable: str) -> str:
    """What ``<executable> --help`` prints, from the installed console script."""
    result = subprocess.run([str(BIN / executable), '--help'], capture_output=True, text=True,
                            timeout=RUN_BUDGET_S, check=False, env=sim_process.environment())
    assert result.returncode == 0, result.stderr
    return result.stdout


def options(words: tuple[str, ...]) -> list[str]:
    """The ``--options`` among ``words`` (``--name=value`` counts as ``--name``)."""
    return [word.partition('=')[0] for word in words if word.startswith('--')]


def check_options(command: Command, executable: str, words: tuple[str, ...]) -> None:
    """Every option of ``words`` is one ``executable --help`` lists."""
    text = help_text(executable)
    for option in options(words):
        assert re.search(rf'(?<![\w-]){re.escape(option)}(?![\w-])', text), \
            f'{command.where}: {executable} has no option {option}'


# sim_node set-ups: the -p arguments of a command that starts it.

@dataclasses.dataclass(frozen=True)
class Setup:
    """A sim_node start as the docs give it: its ``-p`` pairs, raw, in order."""

    parameters: tuple[tuple[str, str], ...] = ()

    def external(self) -> bool:
        """Whether it needs files this repository does not have (another package, a placeholder)."""
        return any(PLACEHOLDER in value or re.search(r'@prefix:(?!pan_tilt_sim@)', value)
                   for _, value in self.parameters)

    def resolved(self) -> tuple[tuple[str, str], ...]:
        """The pairs with this package's prefix and checkout-relative paths made absolute."""
        prefix = str(package_share().parents[1])
        out = []
        for name, value in self.parameters:
            value = value.replace(f'@prefix:{PACKAGE}@', prefix)
            if name in ('robot_description_file', 'controllers_file') and \
                    not value.startswith(('/', 'package://', 'file://')):
                value = str(REPO / value)
            if name == 'record' and value:
                value = tempfile.mkdtemp(dir=_BAGS.name) + '/' + pathlib.Path(value).name
            out.append((name, value))
        return tuple(out)


def ros_parameters(command: Command, words: tuple[str, ...]) -> Setup:
    """The ``-p name:=value`` pairs after ``--ros-args``; ``-r`` remaps are checked for form."""
    if not words:
        return Setup()
    assert words[0] == '--ros-args', f'{command.where}: expected --ros-args, got {words[0]}'
    pairs, rest = [], list(words[1:])
    while rest:
        flag = rest.pop(0)
        if flag == '-r' and rest:  # a remap: a topic of the node's to a name of the user's
            source, separator, target = rest.pop(0).partition(':=')
            assert separator and source.startswith('/') and target.startswith('/'), (
                f'{command.where}: -r {source} is not /from:=/to')
            continue
        assert flag == '-p' and rest, f'{command.where}: unchecked ROS argument {flag}'
        name, separator, value = rest.pop(0).partition(':=')
        assert separator, f'{command.where}: -p {name} has no :='
        pairs.append((name, value))
    return Setup(tuple(pairs))


def parameter_value(text: str):
    """A ``-p`` value as rcl reads it: YAML."""
    return yaml.safe_load(text)


@dataclasses.dataclass(frozen=True)
class Started:
    """What a sim_node set-up created: its parameters (with their types) and its topics."""

    parameters: dict
    publishers: dict
    subscriptions: dict


@functools.lru_cache
def started(setup: Setup) -> Started:
    """Build sim_node in-process with ``setup``'s parameters; what it created."""
    types = dict(started(Setup()).parameters) if setup.parameters else {}
    overrides = {}
    for name, text in setup.resolved():
        value = parameter_value(text)
        if isinstance(value, int) and not isinstance(value, bool) and \
                types.get(name) == 'double':
            value = float(value)  # rcl takes an integer for a double parameter too
        overrides[name] = value
    with sim_node(**overrides) as sim:
        parameters = {name: parameter.type_.name.lower()
                      for name, parameter in sim.node.get_parameters_by_prefix('').items()}
        publishers, subscriptions = sim.own_topics()
    return Started(parameters, publishers, subscriptions)


def own_parameter_names() -> set[str]:
    """sim_node's parameters whatever the robot: those of the pan/tilt and of the arm."""
    arm = Setup((('robot_description_file', 'urdf/three_joint_arm.xacro'),))
    return set(started(Setup()).parameters) | set(started(arm).parameters)


def check_setup(command: Command, setup: Setup) -> None:
    """Every ``-p`` is a sim_node parameter, and a set-up of this repository's files starts."""
    known = own_parameter_names()
    for name, _ in setup.parameters:
        assert name in known, f'{command.where}: sim_node has no parameter {name!r}'
    if not setup.external():
        started(setup)  # raises the one-line ConfigurationError where it does not start


def command_topic_types(kind: type = CommandTopic) -> dict[str, set[str]]:
    """Topic (last name part) -> message types of every controller type's ``kind`` of topic."""
    table: dict[str, set[str]] = {}
    for cls in CONTROLLER_CLASSES:
        for endpoint in example_controller(cls).ros_surface():
            if isinstance(endpoint, kind):
                table.setdefault(endpoint.name.rpartition('/')[2], set()).add(endpoint.message)
    return table


def message_class(type_name: str) -> type:
    """``std_msgs/msg/Float64`` -> the class."""
    package, kind, name = type_name.split('/')
    return getattr(importlib.import_module(f'{package}.{kind}'), name)


def fill(message, values: dict, where: str) -> None:
    """Set ``values`` (a ``ros2 topic pub`` YAML mapping) on ``message``: every field must exist."""
    fields = message.get_fields_and_field_types()
    for name, value in values.items():
        assert name in fields, f'{where}: {type(message).__name__} has no field {name!r}'
        field_type = fields[name]
        if isinstance(value, dict):
            fill(getattr(message, name), value, where)
        elif isinstance(value, list) and value and isinstance(value[0], dict):
            element = message_class(re.sub(r'^sequence<([\w]+)/([\w]+)>$', r'\1/msg/\2',
                                           field_type))
            items = []
            for item in value:
                items.append(element())
                fill(items[-1], item, where)
            setattr(message, name, items)
        else:
            try:
                setattr(message, name, value)
            except (AssertionError, TypeError, ValueError) as error:
                raise AssertionError(f'{where}: {type(message).__name__}.{name} cannot take '
                                     f'{value!r} ({field_type}): {error}') from None


def check_topic_pub(command: Command, setup: Setup, topic: str, type_name: str,
                    data: str) -> None:
    """The data fills the message, and sim_node (or, elsewhere, a controller) takes the topic."""
    fill(message_class(type_name)(), yaml.safe_load(data), command.where)
    if setup.external():
        types = command_topic_types().get(topic.rpartition('/')[2], set())
        assert type_name in types, \
            f'{command.where}: no controller type subscribes {topic} as {type_name}'
    else:
        subscriptions = started(setup).subscriptions
        assert subscriptions.get(topic) == type_name, \
            f'{command.where}: sim_node ({setup.parameters}) subscribes {topic} as ' \
            f'{subscriptions.get(topic)}, not {type_name}'


def check_topic_echo(command: Command, setup: Setup, topic: str) -> None:
    """sim_node publishes the topic in this set-up."""
    if setup.external():
        assert topic.rpartition('/')[2] in command_topic_types(StateTopic), \
            f'{command.where}: no controller type publishes {topic}'
    else:
        assert topic in started(setup).publishers, \
            f'{command.where}: sim_node ({setup.parameters}) does not publish {topic}'


def launch_arguments() -> set[str]:
    """The arguments pan_tilt.launch.py declares."""
    text = (REPO / 'launch' / 'pan_tilt.launch.py').read_text(encoding='utf-8')
    return set(re.findall(r"DeclareLaunchArgument\('(\w+)'", text))


# Examples run by another test, with the arguments the docs give them.
EXAMPLES_RUN_ELSEWHERE = {
    'examples/depth_snapshot.py': 'test/end_to_end/test_depth_example.py',
    'examples/spawn_and_step.py': 'test/end_to_end/test_simulation_interfaces_process.py',
}


def run_example(command: Command, setup: Setup, script: str, arguments: tuple[str, ...]) -> None:
    """Run the example against a sim_node process started with ``setup`` (as fast as it goes)."""
    ros_args = [item for name, value in setup.resolved() for item in ('-p', f'{name}:={value}')]
    process = sim_process.start(*ros_args, '-p', 'real_time_factor:=0', start_new_session=True)
    try:
        result = subprocess.run(
            [sys.executable, str(REPO / script), *arguments, '--timeout', str(RUN_BUDGET_S - 30)],
            capture_output=True, text=True, env=sim_process.environment(),
            timeout=RUN_BUDGET_S, check=False)
    finally:
        sim_process.stop(process, STOP_BUDGET_S)
    assert result.returncode == 0, f'{command.where}: {script} failed\n{result.stdout}' \
        f'{result.stderr}'


def check_example(command: Command, setup: Setup, words: tuple[str, ...]) -> None:
    """Run the example here, or find the test that runs it with these arguments."""
    script, arguments = words[0], words[1:]
    assert (REPO / script).is_file(), f'{command.where}: no {script}'
    if script in EXAMPLES_RUN_ELSEWHERE:
        test_text = (REPO / EXAMPLES_RUN_ELSEWHERE[script]).read_text(encoding='utf-8')
        assert pathlib.PurePath(script).name in test_text
        for argument in arguments:
            if argument.startswith('--') or re.fullmatch(r'[-\d.]+', argument):
                assert f"'{argument}'" in test_text, \
                    f'{command.where}: {EXAMPLES_RUN_ELSEWHERE[script]} does not run {argument}'
        return
    run_example(command, setup, script, arguments)


def run_console_script(command: Command, executable: str, arguments: tuple[str, ...],
                       cwd: pathlib.Path) -> None:
    """Run an installed console script as the docs give it, in ``cwd``; it must exit 0."""
    result = subprocess.run([str(BIN / executable), *arguments], cwd=cwd, capture_output=True,
                            text=True, timeout=RUN_BUDGET_S, check=False,
                            env=sim_process.environment())
    assert result.returncode == 0, f'{command.where}: {executable} failed\n{result.stderr}'


# Console scripts cheap enough to run as the docs give them.
RUN_AS_GIVEN = {'step_response'}


def check_executable(command: Command, executable: str, arguments: tuple[str, ...],
                     tmp_path: pathlib.Path) -> None:
    """An installed executable with these options (sim_node: parameters); run the cheap ones."""
    assert executable in executables(), f'{command.where}: {PACKAGE} has no executable {executable}'
    if executable == 'sim_node':
        check_setup(command, ros_parameters(command, arguments))
        return
    check_options(command, executable, arguments)
    if executable in RUN_AS_GIVEN:
        run_console_script(command, executable, arguments, tmp_path)


def check_run_tests(command: Command, arguments: tuple[str, ...]) -> None:
    """Markers are registered and paths exist."""
    markers = (REPO / 'test' / 'conftest.py').read_text(encoding='utf-8')
    words = list(arguments)
    while words:
        word = words.pop(0)
        if word == '-m':
            marker = words.pop(0)
            assert f"'{marker}:" in markers, f'{command.where}: no pytest marker {marker}'
        elif not word.startswith('-'):
            assert (REPO / word).exists(), f'{command.where}: no {word}'


@functools.cache
def pytest_help() -> str:
    """``pytest --help`` as installed here: with this package's plugin and pytest-xdist."""
    return subprocess.run([str(BIN / 'pytest'), '--help'], capture_output=True, text=True,
                          cwd=tempfile.gettempdir(), timeout=RUN_BUDGET_S, check=True).stdout


def check_pytest(command: Command, arguments: tuple[str, ...]) -> None:
    """Each option is one pytest knows (this package's plugin's too); paths exist."""
    for word in arguments:
        if word.startswith('-'):
            option = word.partition('=')[0]
            assert re.search(rf'(?<![\w-]){re.escape(option)}(?![\w-])', pytest_help()), \
                f'{command.where}: pytest has no option {option}'
        elif not re.fullmatch(r'\d+', word):  # an option's number, else a path
            assert (REPO / word).exists(), f'{command.where}: no {word}'


def check_environment(command: Command) -> None:
    """Each variable set before a command is one the package's scripts or tests read."""
    sources = [*(REPO / 'scripts').iterdir(), *(REPO / 'test').glob('*.py'),
               *(REPO / 'pan_tilt_sim').rglob('*.py')]
    for name, _ in command.environment:
        assert any(name in path.read_text(encoding='utf-8') for path in sources
                   if path.is_file()), f'{command.where}: nothing reads {name}'


def check(command: Command, setup: Setup, tmp_path: pathlib.Path) -> Setup:
    """Check or run one command; return the sim_node set-up in force after it."""
    check_environment(command)
    words = command.words
    head, rest = words[0], words[1:]
    if head in GENERAL_TOOLS:
        return setup
    if head == 'scripts/run_sim.sh':
        assert os.access(REPO / head, os.X_OK), f'{command.where}: {head} is not executable'
        viewer = rest[:1] == ('--viewer',)
        if viewer:  # run_sim.sh's own option: the view's package, and viewer:=true
            assert 'viewer:=true' in (REPO / head).read_text(encoding='utf-8'), command.where
            rest = rest[1:]
        new = ros_parameters(command, rest)
        # The view on any free port: the docs' 8080 may be taken where the tests run.
        check_setup(command, Setup(new.parameters + (('viewer', 'true'), ('viewer.port', '0')))
                    if viewer else new)
        return new
    if head == 'scripts/run_tests.sh':
        assert os.access(REPO / head, os.X_OK), f'{command.where}: {head} is not executable'
        check_run_tests(command, rest)
        return setup
    if head == 'scripts/build_interfaces.sh':
        result = subprocess.run([str(REPO / head), *rest], capture_output=True, text=True,
                                timeout=RUN_BUDGET_S, check=False,
                                env={**os.environ, 'PAN_TILT_SIM_VENV': sys.prefix})
        assert result.returncode == 0, f'{command.where}: {result.stderr}'
        return setup
    if head == '.venv/bin/python':
        if rest[0] == '-m':
            result = subprocess.run([sys.executable, '-P', *rest], capture_output=True, text=True,
                                    cwd=REPO, timeout=RUN_BUDGET_S, check=False,
                                    env=sim_process.environment())
            assert result.returncode == 0, f'{command.where}: {result.stdout}{result.stderr}'
        else:
            check_example(command, setup, rest)
        return setup
    if head == '.venv/bin/pytest':
        check_pytest(command, rest)
        return setup
    if head.startswith('.venv/bin/'):
        check_executable(command, head.rpartition('/')[2], rest, tmp_path)
        return setup
    if head == 'ros2':
        return check_ros2(command, setup, rest, tmp_path)
    if words[:3] == ('sudo', 'apt-get', 'install'):
        # The system packages the scripts themselves ask for (or install, in CI).
        named = ''.join((REPO / path).read_text(encoding='utf-8') for path in (
            '.ci/run', 'scripts/_find_python.sh', 'scripts/_prepare_venv.sh'))
        for package in words[3:]:
            assert re.search(rf'(?<![\w.-]){re.escape(package)}(?![\w.-])', named), \
                f'{command.where}: the scripts never name the package {package}'
        return setup
    if head == 'colcon':
        assert f'<name>{PACKAGE}</name>' in (REPO / 'package.xml').read_text(encoding='utf-8')
        assert rest[rest.index('--packages-select') + 1] == PACKAGE, command.where
        return setup
    if head == 'rosdep':
        assert 'pybullet' in (REPO / 'package.xml').read_text(encoding='utf-8'), command.where
        return setup
    pytest.fail(f'{command.where}: no check for this command: {shlex.join(words)}')


def check_ros2(command: Command, setup: Setup, words: tuple[str, ...],
               tmp_path: pathlib.Path) -> Setup:
    """Check a ros2cli command's pan_tilt_sim parts; return the set-up in force after it."""
    verb = words[0]
    if verb == 'run':
        assert words[1] == PACKAGE, f'{command.where}: not this package: {words[1]}'
        check_executable(command, words[2], words[3:], tmp_path)
        return ros_parameters(command, words[3:]) if words[2] == 'sim_node' else setup
    if verb == 'launch':
        assert words[1] == PACKAGE and (REPO / 'launch' / words[2]).is_file(), command.where
        declared = launch_arguments()
        for argument in words[3:]:
            name, _, value = argument.partition(':=')
            assert name in declared, f'{command.where}: {words[2]} has no argument {name}'
            value = value.replace(f'@prefix:{PACKAGE}@/share/{PACKAGE}/', f'{REPO}/')
            if name == 'model':
                assert pathlib.Path(value).is_file(), f'{command.where}: no {value}'
        return setup
    if words[:2] == ('topic', 'pub'):
        arguments, rest = [], list(words[2:])
        while rest:  # ros2 topic pub's options, those with a value first
            word = rest.pop(0)
            if word in ('-r', '--rate', '-t', '--times', '-w', '--wait-matching-subscriptions'):
                rest.pop(0)
            elif not word.startswith('-'):
                arguments.append(word)
        topic, type_name, data = arguments
        check_topic_pub(command, setup, topic, type_name, data)
        return setup
    if words[:2] == ('topic', 'echo'):
        check_topic_echo(command, setup, words[2])
        return setup
    if words[:2] == ('action', 'send_goal'):
        name, type_name, goal = [word for word in words[2:] if not word.startswith('-')]
        package, kind, action = type_name.split('/')
        assert kind == 'action', f'{command.where}: {type_name} is not an action type'
        goal_class = getattr(importlib.import_module(f'{package}.action'), action).Goal
        fill(goal_class(), yaml.safe_load(goal), command.where)
        served = {(endpoint.name.rpartition('/')[2], endpoint.action)
                  for cls in CONTROLLER_CLASSES
                  for endpoint in example_controller(cls).ros_surface()
                  if isinstance(endpoint, ActionServer)}
        assert (name.rpartition('/')[2], type_name) in served, \
            f'{command.where}: no controller type serves {name} as {type_name}'
        return setup
    if words[:2] == ('param', 'set'):
        node, name = words[2], words[3]
        assert node == f'/{NODE_NAME}', f'{command.where}: sim_node is /{NODE_NAME}, not {node}'
        assert name in started(setup).parameters, f'{command.where}: no parameter {name}'
        return setup
    pytest.fail(f'{command.where}: no check for ros2 {verb}')


@pytest.mark.parametrize('doc', DOCS, ids=doc_id)
def test_every_command_in_the_docs_runs_or_matches_the_code(doc, tmp_path):
    setup = Setup()  # each file starts from the default sim_node
    for command in commands(doc):
        setup = check(command, setup, tmp_path)


def test_a_command_nobody_checks_fails(tmp_path):
    unknown = Command('README.md', 1, (), ('make', 'install'))
    with pytest.raises(pytest.fail.Exception, match='README.md:1: no check for this command'):
        check(unknown, Setup(), tmp_path)


def test_a_parameter_sim_node_lacks_is_named_with_its_place(tmp_path):
    typo = Command('docs/x.md', 7, (), ('scripts/run_sim.sh', '--ros-args', '-p',
                                         'real_time_factr:=0'))
    with pytest.raises(AssertionError,
                       match="docs/x.md:7: sim_node has no parameter 'real_time_factr'"):
        check(typo, Setup(), tmp_path)


def test_a_topic_of_the_wrong_type_is_named_with_its_place(tmp_path):
    wrong = Command('docs/x.md', 3, (), ('ros2', 'topic', 'pub', '--once',
                                         '/ex_urdf_pan_tilt/joint1_position_controller/command',
                                         'std_msgs/msg/Float64MultiArray', '{data: [1.0]}'))
    with pytest.raises(AssertionError, match='docs/x.md:3: sim_node .* subscribes'):
        check(wrong, Setup(), tmp_path)
