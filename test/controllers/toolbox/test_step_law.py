"""The law rows' layout: named once, in row order, for the compiled loop to be checked against.

That the compiled step's copy is the same layout is
test/sim/test_compiled_step.py's business; here: the names and the
constants agree, and the rows the laws build have the layout's size.
"""

from pan_tilt_sim.controllers.toolbox import step_law


def test_the_field_names_name_the_row_indices_in_order():
    assert [getattr(step_law, name) for name in step_law.FIELDS] == list(range(step_law.ROW_SIZE))


def test_the_kind_names_name_the_kind_codes():
    assert step_law.KINDS == {'POSITION_PID': step_law.POSITION_PID,
                              'VELOCITY_PID': step_law.VELOCITY_PID, 'EFFORT': step_law.EFFORT}
    assert len(set(step_law.KINDS.values())) == len(step_law.KINDS)


def test_the_rows_the_laws_build_have_every_field():
    pid_values = [1.0, 2.0, 3.0, -4.0, 4.0, 1.0, 0.5, 0.25, float('nan')]
    row = step_law.pid_row(step_law.VELOCITY_PID, pid_values, 6.0, 7.0, 8.0, 9.0)
    assert len(row) == step_law.ROW_SIZE
    assert [row[step_law.KIND], row[step_law.P_GAIN], row[step_law.EFFORT_LIMIT],
            row[step_law.COMMAND], row[step_law.OUTPUT]] == [step_law.VELOCITY_PID, 1.0, 7.0,
                                                             9.0, 0.25]
    effort = step_law.effort_row(5.0)
    assert len(effort) == step_law.ROW_SIZE
    assert (effort[step_law.KIND], effort[step_law.COMMAND]) == (step_law.EFFORT, 5.0)
