"""A configuration error is one line, whatever the names it quotes."""

from pan_tilt_sim.errors import ConfigurationError, DescriptionError


def test_a_line_break_in_a_quoted_name_reads_as_an_escape_not_a_second_line():
    error = DescriptionError("left_wheel_names: joint '\n' is not in the URDF")
    assert str(error) == "left_wheel_names: joint '\\n' is not in the URDF"
    assert '\n' not in str(ConfigurationError('a\r\nb'))
