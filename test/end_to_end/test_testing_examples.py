"""examples/testing, a user's package tested with the plugin, passes as CI runs it: pytest -n 2."""

from __future__ import annotations

import pathlib
import re

from pytest_runs import run_pytest, spare_domain_base

EXAMPLES = pathlib.Path(__file__).resolve().parents[2] / 'examples' / 'testing'
EXAMPLE_TESTS = 4


def test_the_testing_examples_pass_under_n_2():
    result = run_pytest(EXAMPLES, '-n', '2', '--ros-domain-base', str(spare_domain_base()))
    output = result.stdout + result.stderr
    assert result.returncode == 0, output
    assert re.search(rf'\b{EXAMPLE_TESTS} passed\b', output), output
