"""URDFs whose <ros2_control> hardware is topic_based_ros2_control, written on the fly."""

from __future__ import annotations

import pathlib
import textwrap

from robot_fixtures import JointDef, star_robot_urdf


def topic_based_urdf(interfaces: dict[str, list[str]], *, commands: str = '',
                     states: str = '') -> str:
    """A star robot with one joint per entry, in a TopicBasedSystem block with those interfaces.

    ``commands`` / ``states`` become the block's joint_commands_topic / joint_states_topic.
    """
    urdf = star_robot_urdf([JointDef(name) for name in interfaces], name='star')
    params = ''.join(f'<param name="{name}">{value}</param>' for name, value in (
        ('joint_commands_topic', commands), ('joint_states_topic', states)) if value)
    joints = ''.join(
        f'<joint name="{name}">'
        + ''.join(f'<command_interface name="{i}"/>' for i in names)
        + '<state_interface name="position"/><state_interface name="velocity"/>'
        '<state_interface name="effort"/></joint>' for name, names in interfaces.items())
    block = textwrap.dedent(f"""
        <ros2_control name="star" type="system">
          <hardware><plugin>topic_based_ros2_control/TopicBasedSystem</plugin>{params}</hardware>
          {joints}
        </ros2_control>""")
    return urdf.replace('</robot>', block + '</robot>')


def topic_based_urdf_file(folder: pathlib.Path, interfaces: dict[str, list[str]],
                          **topics: str) -> pathlib.Path:
    """Write :func:`topic_based_urdf` to ``folder/star.urdf``; return the path."""
    path = folder / 'star.urdf'
    path.write_text(topic_based_urdf(interfaces, **topics), encoding='utf-8')
    return path
