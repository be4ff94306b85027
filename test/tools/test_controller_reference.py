"""controller_reference: the README's controller table and docs/controllers.md follow the code."""

import dataclasses

from pan_tilt_sim.controllers.framework.registry import CONTROLLER_CLASSES
from pan_tilt_sim.controllers.trajectory.joint_trajectory_controller import (
    JointTrajectoryController,
)
from pan_tilt_sim.tools import controller_reference


def test_the_committed_reference_matches_the_specs_and_surfaces(repo_root):
    stale = controller_reference.stale_files(repo_root)
    assert not stale, (f'out of date: {", ".join(map(str, stale))}; run python -m '
                       'pan_tilt_sim.tools.controller_reference --write')


def test_a_changed_default_makes_the_reference_stale(repo_root, monkeypatch):
    spec = JointTrajectoryController.parameters
    changed = spec.extend(dataclasses.replace(spec['action_monitor_rate'], default=99.0))
    monkeypatch.setattr(JointTrajectoryController, 'parameters', changed)
    stale = controller_reference.stale_files(repo_root)
    assert repo_root / 'docs' / 'controllers.md' in stale
    assert '`99.0`' in stale[repo_root / 'docs' / 'controllers.md']


def test_the_reference_names_every_type_string_and_parameter():
    docs = controller_reference.docs_markdown()
    table = controller_reference.readme_table()
    for cls in CONTROLLER_CLASSES:
        for type_name in cls.type_names:
            assert f'`{type_name}`' in docs and f'`{type_name}`' in table
        for param in cls.parameters:
            assert f'`{param.name}`' in docs


def test_the_readme_table_shows_each_types_topics():
    table = controller_reference.readme_table()
    assert 'subscribes `~/commands` (std_msgs/msg/Float64MultiArray)' in table
    assert 'publishes `joint_states` (sensor_msgs/msg/JointState)' in table
    assert 'serves `~/follow_joint_trajectory` (control_msgs/action/FollowJointTrajectory)' \
        in table
