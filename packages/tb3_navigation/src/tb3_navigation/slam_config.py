"""The SLAM's parameters (tb3_navigation.slam): gmapping's names and TurtleBot3's values, checked as
the nodes read them (tb3_common.params). No ROS here."""
import dataclasses

from tb3_common.params import Checked, fail, non_negative, number, parameter, positive


@dataclasses.dataclass(frozen=True)
class SlamConfig(Checked):
    """gmapping's parameters (its names) with turtlebot3_slam's values, and the few of our own.

    gmapping's particle filter's own (particles, resampleThreshold, ogain,
    lsigma, kernelSize, ll/lasample*) mean nothing here: the node
    (gmapping.node) takes them and says so. Its odometry error model (srr,
    srt, str, stt) weighs the pose graph's constraints where the pose
    followed the odometry, as it spreads gmapping's particles. odom_weight 20:
    the worst pose error on the house tour was 6.4 cm with 0, 2.4 cm with 20,
    5.4 cm with 80.
    """
    maxUrange: float = parameter(3.0, 'm: beams are used for the map and matching up to here; longer ones only clear',
                                 positive, 'm')
    maxRange: float = parameter(0.0, "m: hits longer than this are dropped whole; 0 = the scan's range_max",
                                non_negative, 'm')
    delta: float = parameter(0.05, "m: the map's cell", positive, 'm')
    xmin: float = parameter(-10.0, "m: the map's extent in the map frame; its origin is (xmin, ymin)", None, 'm')
    ymin: float = parameter(-10.0, 'm', None, 'm')
    xmax: float = parameter(10.0, 'm', None, 'm')
    ymax: float = parameter(10.0, 'm', None, 'm')
    linearUpdate: float = parameter(1.0, 'm driven before a scan is added to the map', non_negative, 'm')
    angularUpdate: float = parameter(0.2, 'rad turned before a scan is added to the map', non_negative, 'rad')
    temporalUpdate: float = parameter(0.5, 's since the last added scan before one is added anyway; < 0: never',
                                      None, 's')
    map_update_interval: float = parameter(2.0, 's between two maps the node publishes', positive, 's')
    occ_thresh: float = parameter(0.25, "share of a cell's sightings that were hits above which it is occupied",
                                  number(0.0, 1.0, high_open=True))
    minimumScore: float = parameter(50.0, "a match scoring less (about: fewer beams on the map's walls) is not used",
                                    non_negative)
    sigma: float = parameter(0.05, "m: the likelihood field's width", positive, 'm')
    lstep: float = parameter(0.05, 'm: step of the correlative search', positive, 'm')
    astep: float = parameter(0.05, 'rad: step of the correlative search', positive, 'rad')
    iterations: int = parameter(5, 'Gauss-Newton steps after the search', number(0))
    odom_weight: float = parameter(20.0, "end points' worth of pull towards the odometry's prediction in those steps",
                                   non_negative)
    lskip: int = parameter(0, 'match with every (lskip + 1)-th beam', number(0))
    search_linear: float = parameter(0.10, "m: the correlative search's reach around the prediction", non_negative,
                                     'm')
    search_angular: float = parameter(0.10, 'rad: its reach in heading', non_negative, 'rad')
    jump_distance: float = parameter(0.5, "m between two scans' odometry poses taken for a jump, not a drive",
                                     positive, 'm')
    jump_angle: float = parameter(1.0, 'rad, likewise (the Burger turns at most 2.84 rad/s: 0.57 rad in 0.2 s)',
                                  positive, 'rad')
    # gmapping's odometry error model: how far the graph's constraints trust a stretch the pose followed the
    # odometry unmatched (tb3_navigation.loop_closure.information).
    srr: float = parameter(0.1, 'odometry error in translation as a function of translation (m/m)', non_negative)
    srt: float = parameter(0.2, 'odometry error in translation as a function of rotation (m/rad)', non_negative)
    str: float = parameter(0.1, 'odometry error in rotation as a function of translation (rad/m)', non_negative)
    stt: float = parameter(0.2, 'odometry error in rotation as a function of rotation (rad/rad)', non_negative)
    # Loop closure (tb3_navigation.loop_closure), under slam_toolbox's names where they mean the same.
    do_loop_closing: bool = parameter(True, 'match a scan that comes back near old ones against them and correct '
                                            'the poses since and the map')
    loop_search_maximum_distance: float = parameter(3.0, 'm: old scans this near the pose are matched against',
                                                    positive, 'm')
    loop_match_minimum_chain_size: int = parameter(10, 'old scans (0.2 m of driving apart) needed near the pose',
                                                   number(1))
    loop_match_minimum_response_fine: float = parameter(
        0.6, "a closing match's least score per end point (1: every point on an old wall)",
        number(0.0, 1.0, low_open=True))
    loop_search_linear: float = parameter(0.5, "m: the closing match's search reach around the pose",
                                          non_negative, 'm')
    loop_search_angular: float = parameter(0.3, 'rad: its reach in heading', non_negative, 'rad')

    def check_together(self):
        if self.maxRange and self.maxRange < self.maxUrange:
            fail('maxRange', self.maxRange, "must be 0 (the scan's range_max) or >= maxUrange (%r)" % self.maxUrange)
        for low, high in (('xmin', 'xmax'), ('ymin', 'ymax')):
            if getattr(self, high) - getattr(self, low) < self.delta:
                fail(high, getattr(self, high), 'must exceed %s (%r) by delta at least' % (low, getattr(self, low)))
