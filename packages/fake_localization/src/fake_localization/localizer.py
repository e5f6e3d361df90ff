"""fake_localization's arithmetic in the plane, and its parameters. No ROS here.

The original (ros-planning/navigation, noetic, fake_localization.cpp) keeps
one offset, a transform that starts as (-delta_x, -delta_y, -delta_yaw),
and takes each ground-truth pose through it: the estimate is
offset * truth. Its tf map -> odom is the one that puts the base frame
there, given odom -> base at the truth's stamp: estimate * (odom -> base)^-1.
An initial pose (rviz's 2D Pose Estimate) moves the offset so that the base
lands on it: offset := pose * (base in map)^-1 * offset.

The original does this in 3-D; here it is done on plane poses (x, y, yaw),
the height, roll and pitch of the truth dropped: a TurtleBot3 on its floor
has none, and the deltas are planar in the original too.
"""
import dataclasses
import math

from tb3_common import pose2d
from tb3_common.params import Checked, frame_id, non_negative, parameter


@dataclasses.dataclass(frozen=True)
class FakeLocalizationConfig(Checked):
    """fake_localization's parameters by its names, with its defaults (noetic)."""
    odom_frame_id: str = parameter('odom', "odometry's frame: the child of the tf this node sends", frame_id)
    base_frame_id: str = parameter('base_link', "the robot's frame (the original's default, base_link, not "
                                   "TurtleBot3's base_footprint)", frame_id)
    global_frame_id: str = parameter('map', 'the frame of the estimate and the parent of the tf sent', frame_id)
    delta_x: float = parameter(0.0, 'the estimate is the truth moved by -delta_x (with delta_y and delta_yaw)',
                               unit='m')
    delta_y: float = parameter(0.0, 'the estimate is the truth moved by -delta_y', unit='m')
    delta_yaw: float = parameter(0.0, 'the estimate is the truth turned by -delta_yaw', unit='rad')
    transform_tolerance: float = parameter(0.1, 'tf global -> odom is post-dated by this', non_negative, 's')


def finite(pose):
    return all(math.isfinite(value) for value in pose)


class FakeLocalizer(object):
    """The offset, the last estimate, and the transforms that follow from them."""

    def __init__(self, config):
        self.offset = (-config.delta_x, -config.delta_y, -config.delta_yaw)
        self.estimate = None  # the last estimate (x, y, yaw) in the global frame

    def update(self, truth, base_in_odom):
        """(estimate, odom's pose in the global frame) for a ground-truth pose and odom -> base at its
        stamp; ValueError if either has a NaN or an inf (nothing is kept then)."""
        if not finite(truth) or not finite(base_in_odom):
            raise ValueError('a pose with NaN or inf in it: truth %s, odom -> base %s' % (truth, base_in_odom))
        estimate = tuple(pose2d.compose(self.offset, truth))
        self.estimate = estimate
        return estimate, tuple(pose2d.compose(estimate, pose2d.inverse(base_in_odom)))

    def set_pose(self, pose):
        """An initial pose: from the next truth on, the estimate is `pose` where the base is now.
        ValueError if there is no estimate yet (the original's "Failed to lookup transform!") or the
        pose is not finite."""
        if not finite(pose):
            raise ValueError('an initial pose with NaN or inf in it: %s' % (tuple(pose),))
        if self.estimate is None:
            raise ValueError('no ground truth yet, so no pose of the base to move')
        delta = pose2d.compose(pose, pose2d.inverse(self.estimate))
        self.offset = tuple(pose2d.compose(delta, self.offset))
