"""What xacro does with $(find PKG): the facts the description layer relies on.

A failure here means xacro (or the ament index) changed, not pan_tilt_sim.
"""

import xml.etree.ElementTree as ET

import mesh_fixtures as mf
import pytest
import xacro

from pan_tilt_sim.model.resources import localize_meshes

XACRO_MAIN = '''<?xml version="1.0"?>
<robot xmlns:xacro="http://www.ros.org/wiki/xacro" name="x">
  <xacro:arg name="mesh" default="base"/>
  <xacro:include filename="$(find my_robot_pkg)/urdf/arm.xacro"/>
  <link name="base_link"><collision><geometry>
    <mesh filename="$(find my_robot_pkg)/meshes/collision/$(arg mesh).stl"/>
  </geometry></collision></link>
  <xacro:arm/>
</robot>
'''


XACRO_ARM = '''<?xml version="1.0"?>
<robot xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:macro name="arm"><link name="arm_link"><collision><geometry>
    <mesh filename="package://my_robot_pkg/meshes/collision/arm.stl"/>
  </geometry></collision></link></xacro:macro>
</robot>
'''


def test_xacro_find_uses_the_ament_index(my_robot_share, tmp_path, cache_dir):
    """Xacro resolves $(find PKG) through AMENT_PREFIX_PATH, in includes too."""
    (my_robot_share / 'urdf' / 'arm.xacro').write_text(XACRO_ARM)
    main = tmp_path / 'main.xacro'
    main.write_text(XACRO_MAIN)
    document = xacro.process_file(str(main), mappings={'mesh': 'base'})
    robot = ET.fromstring(document.toxml())
    assert robot.find('link/collision/geometry/mesh').get('filename') == str(
        my_robot_share / 'meshes' / 'collision' / 'base.stl')
    done = localize_meshes(robot, main.parent, cache_dir)
    assert [m.loadable for m in done] == [my_robot_share / mf.MY_ROBOT_MESHES['base_collision'],
                                          my_robot_share / mf.MY_ROBOT_MESHES['arm_collision']]


def test_xacro_find_of_an_unknown_package_raises_xacro_exception(tmp_path, monkeypatch):
    """Xacro reports an unknown $(find) package as XacroException (the caller maps it)."""
    monkeypatch.setenv('AMENT_PREFIX_PATH', str(tmp_path))
    main = tmp_path / 'main.xacro'
    main.write_text(XACRO_MAIN)
    with pytest.raises(xacro.XacroException, match="package 'my_robot_pkg' not found"):
        xacro.process_file(str(main))
