"""Friction tags: `<gazebo reference="LINK">` `<mu1>`/`<mu2>`, by link, as urdf2sdf reads them."""

import pathlib

import pytest

from pan_tilt_sim.errors import DescriptionError
from pan_tilt_sim.model.surfaces import Surface
from pan_tilt_sim.model.urdf import parse_urdf

SOURCE = pathlib.Path('hand.urdf')


def hand(*gazebo: str) -> str:
    """Return a palm with one finger on joint 'slide', and ``gazebo`` blocks."""
    return f"""<robot name="hand">
      <link name="palm"/>
      <link name="finger"/>
      <joint name="slide" type="prismatic"><parent link="palm"/><child link="finger"/>
        <axis xyz="0 1 0"/><limit lower="0" upper="0.04" effort="20" velocity="0.2"/></joint>
      {''.join(gazebo)}
    </robot>"""


def test_a_links_mu1_and_mu2_are_read_by_link():
    model = parse_urdf(hand('<gazebo reference="finger"><mu1>1.5</mu1><mu2>0.8</mu2>'
                            '<material>Gazebo/Grey</material></gazebo>'), SOURCE)
    assert model.link_frictions == {'finger': Surface('finger', 1.5, 0.8)}


def test_a_link_without_the_tags_has_no_entry_and_a_missing_one_is_gazebos_default():
    model = parse_urdf(hand('<gazebo reference="finger"><mu1>0.3</mu1></gazebo>',
                            '<gazebo reference="palm"><selfCollide>true</selfCollide></gazebo>'),
                       SOURCE)
    assert model.link_frictions == {'finger': Surface('finger', 0.3, 1.0)}


def test_blocks_naming_one_link_merge_the_last_value_of_each_tag_wins():
    model = parse_urdf(hand('<gazebo reference="finger"><mu1>0.3</mu1><mu2>0.4</mu2></gazebo>',
                            '<gazebo reference="finger"><mu2>0.9</mu2></gazebo>'), SOURCE)
    assert model.link_frictions == {'finger': Surface('finger', 0.3, 0.9)}


def test_a_reference_that_is_not_a_link_carries_no_surface():
    model = parse_urdf(hand('<gazebo reference="slide"><mu1>0.3</mu1></gazebo>',
                            '<gazebo><mu1>0.3</mu1></gazebo>'), SOURCE)
    assert model.link_frictions == {}


@pytest.mark.parametrize('text', ['-0.1', 'rubber', 'inf', 'nan', ''])
def test_a_value_that_is_not_a_number_at_least_zero_names_the_file_the_link_and_the_tag(text):
    with pytest.raises(DescriptionError, match=r'^hand\.urdf: <gazebo reference="finger">: '
                                               r"<mu2> '.*' must be a number >= 0$"):
        parse_urdf(hand(f'<gazebo reference="finger"><mu2>{text}</mu2></gazebo>'), SOURCE)
