"""odom_parents.parents_in: another node's parent of an odom frame found in raw /tf bytes, without ROS."""
import io

from geometry_msgs.msg import TransformStamped
from tf2_msgs.msg import TFMessage

from tb3_sim_nav.ros.odom_parents import needle, parents_in


def raw(*links):
    message = TFMessage()
    for parent, child, x in links:
        transform = TransformStamped()
        transform.header.frame_id, transform.child_frame_id = parent, child
        transform.transform.translation.x = x
        transform.transform.rotation.w = 1.0
        message.transforms.append(transform)
    buffer = io.BytesIO()
    message.serialize(buffer)
    return buffer.getvalue()


NEEDLES = {'odom': needle('odom'), 'tb3_0/odom': needle('tb3_0/odom')}


def test_a_parent_of_an_odom_frame_is_found_with_its_pose():
    found = parents_in(raw(('map', 'odom', 0.5)), NEEDLES)
    assert found == {'odom': ('map', ((0.5, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0)))}
    found = parents_in(raw(('base_footprint', 'base_link', 0.0), ('tb3_0/map', 'tb3_0/odom', 1.0)), NEEDLES)
    assert list(found) == ['tb3_0/odom'] and found['tb3_0/odom'][0] == 'tb3_0/map'


def test_odom_as_a_parent_or_a_longer_name_is_no_claim():
    assert parents_in(raw(('odom', 'base_footprint', 0.0)), NEEDLES) == {}
    assert parents_in(raw(('map', 'odom_combined', 0.0)), NEEDLES) == {}
    assert parents_in(raw(('map', 'tb3_1/odom', 0.0)), NEEDLES) == {}


def test_wheels_are_not_even_parsed():
    """robot_state_publisher's messages hold no odom frame's name: no deserialisation at all."""
    assert parents_in(b'not a tf message at all', NEEDLES) == {}
