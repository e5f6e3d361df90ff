"""slam_gmapping's parameters as this node takes them. No ROS here.

Every parameter the real node reads (ros-perception/slam_gmapping 1.4.2,
gmapping/src/slam_gmapping.cpp, the version Noetic ships) is taken here, so
that a launch file written for gmapping (ROBOTIS' gmapping_params.yaml, its
multi-robot launch) runs unchanged:

- the SLAM's own (maxUrange, delta, linearUpdate, minimumScore, the
  odometry error model srr..stt...) are tb3_navigation.slam_config.SlamConfig's
  fields, honoured there;
- the wrapper's (frames, throttle_scans, transform_publish_period,
  tf_delay) are NodeConfig's below, honoured by the node;
- those of gmapping's particle filter mean nothing to a SLAM that keeps one
  pose: UNHONOURED names each with why, and the node says so at start for
  those that are set.
"""
import dataclasses
import typing

from tb3_common.params import Checked, non_negative, number, one_of, optional_frame_id, parameter

#: What turtlebot3_slam.launch's slam_methods may ask for: each runs this node (and says so).
METHODS = ('tb3', 'gmapping', 'cartographer', 'hector', 'karto', 'frontier_exploration')

_PARTICLES = 'this SLAM keeps one pose, matched once per scan, not a particle filter'
_SAMPLING = "the sampling of a particle's likelihood around its match; the match here is refined by Gauss-Newton"

#: gmapping's parameters this node takes without effect: name -> why.
UNHONOURED = {
    'particles': _PARTICLES,
    'resampleThreshold': _PARTICLES + ': nothing to resample',
    'ogain': "it smooths the particles' weights; " + _PARTICLES,
    'lsigma': "a beam's noise in the particles' weights; the match here scores beams by sigma",
    'kernelSize': "gmapping's matcher looks this many cells round a beam's end for a hit; the match here "
                  'uses a likelihood field of width sigma',
    'llsamplerange': _SAMPLING, 'llsamplestep': _SAMPLING, 'lasamplerange': _SAMPLING, 'lasamplestep': _SAMPLING,
}


@dataclasses.dataclass(frozen=True)
class NodeConfig(Checked):
    """slam_gmapping's own parameters (its "wrapper" ones), and slam_methods of ours.

    The frames default to TurtleBot3's (gmapping's base_frame is base_link),
    in a namespace to the namespace's (tb3_0/base_footprint...), as ROBOTIS'
    multi-robot launch sets them: empty here means that default.
    """
    base_frame: str = parameter('', "the robot's frame; empty: base_footprint (NAMESPACE/base_footprint in a "
                                    'namespace)', optional_frame_id)
    odom_frame: str = parameter('', "odometry's frame; empty: odom (NAMESPACE/odom)", optional_frame_id)
    map_frame: str = parameter('', "the map's frame; empty: map (NAMESPACE/map)", optional_frame_id)
    throttle_scans: int = parameter(1, 'only every n-th scan is used, as gmapping counts them', number(1))
    transform_publish_period: float = parameter(
        0.05, 's between two map -> odom transforms; 0: one with each scan (gmapping: none)', non_negative, 's')
    tf_delay: typing.Optional[float] = parameter(
        None, 's: map -> odom is stamped this far ahead, so lookups at a scan\'s time succeed; unset: '
              'transform_publish_period', non_negative, 's')
    slam_methods: str = parameter('tb3', "ours: turtlebot3_slam's method asked for; each runs this SLAM and "
                                         'says so', one_of(*METHODS))

    @property
    def stamp_ahead(self):
        """s that map -> odom is stamped ahead of now."""
        return self.transform_publish_period if self.tf_delay is None else self.tf_delay
