"""The model's plugin elements: every model-level <gazebo><plugin>, read once, as data."""

import pathlib
from xml.etree import ElementTree

from pan_tilt_sim.model.plugin_elements import PluginElement, read_plugin_elements

SOURCE = pathlib.Path('robot.urdf')


def elements(text: str) -> tuple[PluginElement, ...]:
    return read_plugin_elements(ElementTree.fromstring(f'<robot name="r">{text}</robot>'), SOURCE)


def test_each_model_plugin_is_read_with_its_attributes_children_and_source():
    (element,) = elements(
        '<gazebo><plugin name="drive" filename="libgazebo_ros_diff_drive.so">'
        '<left_joint> a </left_joint><left_joint>b</left_joint><update_rate>30</update_rate>'
        '<empty/></plugin></gazebo>')
    assert element == PluginElement(
        filename='libgazebo_ros_diff_drive.so', name='drive',
        values={'left_joint': ('a', 'b'), 'update_rate': ('30',), 'empty': ('',)},
        source=str(SOURCE))
    assert element.stem == 'gazebo_ros_diff_drive'


def test_the_ros_block_is_kept_as_written():
    (element,) = elements(
        '<gazebo><plugin filename="libgazebo_ros_p3d.so"><ros><namespace> /demo </namespace>'
        '<remapping>odom:=truth</remapping><remapping>bad</remapping></ros></plugin></gazebo>')
    assert element.has_ros and element.ros_namespace == '/demo'
    assert element.ros_remappings == ('odom:=truth', 'bad')
    assert element.name == '' and 'ros' in element.values


def test_plugins_of_a_referenced_gazebo_block_are_not_model_plugins_and_order_is_kept():
    found = elements(
        '<gazebo reference="base_link"><plugin filename="a"/></gazebo>'
        '<gazebo><plugin filename="b"/><plugin filename="c"/></gazebo>'
        '<gazebo><plugin filename="d"/></gazebo>')
    assert [element.filename for element in found] == ['b', 'c', 'd']
    assert not any(element.has_ros for element in found)
