"""Flags read as gflags reads them (ros_gz_sim's create parses its command line so)."""

import pytest

from pan_tilt_sim.tools.stand_ins.flags import FlagError, FlagExitError, parse_flags

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


def test_undefok_lets_the_unknown_flags_it_names_pass():
    values, leftover, _given = parse_flags(
        ['-undefok=colour,size', '-colour', 'red', '--nosize', '-name', 'a'], DEFAULTS)
    # An unknown flag takes no value (gflags cannot know it takes one): 'red' is left over.
    assert values['name'] == 'a' and leftover == ['red']
    with pytest.raises(FlagError, match="unknown command line flag 'shape'"):
        parse_flags(['--undefok', 'colour', '-shape'], DEFAULTS)


def test_flagfile_reads_one_flag_a_line_and_the_command_line_goes_on(tmp_path):
    flags = tmp_path / 'create.flags'
    flags.write_text('# robot\n--name=arm\n-x=1.5\n\n--allow_renaming\n')
    values, _leftover, given = parse_flags([f'--flagfile={flags}', '-x', '2'], DEFAULTS)
    assert (values['name'], values['allow_renaming'], values['x']) == ('arm', True, 2.0)
    assert given == {'name', 'x', 'allow_renaming'}
    with pytest.raises(FlagError, match='could not read flagfile'):
        parse_flags(['-flagfile', str(tmp_path / 'none')], DEFAULTS)


def test_fromenv_reads_flags_from_flags_variables_and_tryfromenv_may_miss_them():
    environ = {'FLAGS_name': 'arm', 'FLAGS_x': '0.5'}
    values, _leftover, _given = parse_flags(['--fromenv=name,x'], DEFAULTS, environ)
    assert (values['name'], values['x']) == ('arm', 0.5)
    assert parse_flags(['--tryfromenv=topic,name'], DEFAULTS, environ)[0]['name'] == 'arm'
    with pytest.raises(FlagError, match='FLAGS_topic not found in environment'):
        parse_flags(['--fromenv=topic'], DEFAULTS, environ)


@pytest.mark.parametrize(('word', 'code'), [('--help', 1), ('-helpfull', 1), ('--helpshort', 1),
                                            ('--helpxml', 1), ('--version', 0)])
def test_help_and_version_end_the_program_as_gflags_does(word, code):
    with pytest.raises(FlagExitError) as ended:
        parse_flags(['-name', 'a', word], DEFAULTS)
    assert ended.value.code == code
