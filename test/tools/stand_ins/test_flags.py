"""Flags read as gflags reads them (ros_gz_sim's create parses its command line so)."""

import pytest

from pan_tilt_sim.tools.stand_ins.flags import FlagError, parse_flags

DEFAULTS = {'name': '', 'allow_renaming': False, 'x': 0.0, 'topic': ''}


def test_values_follow_their_flag_in_every_spelling():
    values, leftover, given = parse_flags(
        ['-name', 'arm', '--topic=/robot_description', '-x', '-2.5'], DEFAULTS)
    assert (values['name'], values['topic'], values['x']) == ('arm', '/robot_description', -2.5)
    assert leftover == [] and given == {'name', 'topic', 'x'}


def test_a_bool_flag_alone_is_true_and_never_takes_the_next_word():
    values, leftover, _given = parse_flags(['-allow_renaming', 'false', '-name', 'a'], DEFAULTS)
    # As gflags: `-allow_renaming false` sets it true and leaves 'false' over.
    assert values['allow_renaming'] is True and leftover == ['false']
    assert parse_flags(['-allow_renaming=false'], DEFAULTS)[0]['allow_renaming'] is False
    assert parse_flags(['-noallow_renaming'], DEFAULTS)[0]['allow_renaming'] is False


def test_double_dash_ends_the_flags():
    values, leftover, _given = parse_flags(['--', '-name', 'a'], DEFAULTS)
    assert values['name'] == '' and leftover == ['-name', 'a']


@pytest.mark.parametrize(('argv', 'message'), [
    (['-colour', 'red'], "ERROR: unknown command line flag 'colour'"),
    (['-name'], "ERROR: flag '-name' is missing its argument"),
    (['-x', 'left'], "ERROR: illegal value 'left' specified for double flag 'x'"),
    (['-allow_renaming=maybe'], "ERROR: illegal value 'maybe' specified for bool flag"),
])
def test_what_gflags_refuses_is_refused_with_its_words(argv, message):
    with pytest.raises(FlagError, match=message):
        parse_flags(argv, DEFAULTS)
