"""A costmap's parameters as costmap_2d reads them under ~global_costmap/ or ~local_costmap/. No ROS here.

TurtleBot3, the ROS wiki's tutorials and ROS by Example set no `plugins`,
so costmap_2d takes its pre-Hydro parameters: the costmap's own
(CostmapROSConfig: frames, rates, size), the layers' (CostmapConfig, the
core's) and its observation sources (ObservationSource each). As costmap_2d:

- the footprint is `footprint` (a list, or a string of one), else
  `robot_radius` made a 16-corner polygon, each searched from the costmap's
  namespace upwards (a launch may set either once for both costmaps);
- `observation_sources` names the sources, each a namespace of its own
  whose obstacle_range and raytrace_range default to the costmap's; a
  source's data_type defaults to PointCloud, which is refused here (the
  costmaps are marked from laser scans only): a lidar is data_type
  LaserScan. With `observation_sources` unset, TurtleBot3's one source holds
  (the `scan` topic, base_scan, marking and clearing);
- `map_type: voxel` makes a 2D costmap here (a laser's hits are the same
  in both); voxel's own parameters are named as unhonoured;
- the static map's resolution wins over `resolution` for a costmap with
  `static_map` (costmap_2d resizes the costmap to the map).

Defaults are TurtleBot3's (GLOBAL_COSTMAP, LOCAL_COSTMAP) where it sets a
value, costmap_2d's elsewhere. Frame ids may start with "/".
"""
import dataclasses

import yaml

from tb3_common.params import (
    Checked,
    ParameterError,
    fail,
    frame_id,
    non_negative,
    one_of,
    optional_frame_id,
    parameter,
    positive,
)
from tb3_navigation.costmap import CostmapConfig
from tb3_navigation.footprint import circle_footprint

#: turtlebot3_navigation/param/global_costmap_params.yaml and local_costmap_params.yaml (noetic).
GLOBAL_COSTMAP = dict(global_frame='map', robot_base_frame='base_footprint', update_frequency=10.0,
                      publish_frequency=10.0, transform_tolerance=0.5, static_map=True)
LOCAL_COSTMAP = dict(global_frame='odom', robot_base_frame='base_footprint', update_frequency=10.0,
                     publish_frequency=10.0, transform_tolerance=0.5, static_map=False, rolling_window=True,
                     width=3.0, height=3.0, resolution=0.05)
DEFAULTS = {'global_costmap': GLOBAL_COSTMAP, 'local_costmap': LOCAL_COSTMAP}
#: costmap_common_params_burger.yaml's source, when a costmap names none.
TURTLEBOT3_SOURCE = ('scan', dict(sensor_frame='base_scan', data_type='LaserScan', topic='scan', marking=True,
                                  clearing=True))

_VOXEL = 'map_type voxel is taken as costmap here: a 2D grid (a laser marks the same cells in both)'
_HEIGHT = ("a laser's hits lie at its own height (0.17 m on a Burger), inside costmap_2d's default band of 0 "
           'to 2 m: no hit is dropped by height here')
UNHONOURED = dict(
    plugins="the pre-Hydro layers are used whatever `plugins` says (static if static_map, obstacles, inflation)",
    max_obstacle_height=_HEIGHT, min_obstacle_height=_HEIGHT,
    inscribed_radius='the inscribed radius comes from the footprint here',
    unknown_cost_value='map cells of -1 (255) are unknown here', trinary_costmap='the static map is trinary here',
    use_maximum='the static map is written over the costmap here', first_map_only='every new map is taken here',
    subscribe_to_updates='map_updates is not read here: a new map replaces the old',
    combination_method="the obstacles are laid on with 'maximum' here",
    always_send_full_costmap='the whole costmap is always sent here (no costmap_updates)',
    footprint_topic='the footprint does not change at run time here',
    published_footprint_topic='the footprint is published on ~NAME/footprint',
    origin_z=_VOXEL, z_resolution=_VOXEL, z_voxels=_VOXEL, mark_threshold=_VOXEL, unknown_threshold=_VOXEL,
    publish_voxel_map=_VOXEL)
HARMLESS = dict(unknown_cost_value=-1, trinary_costmap=True, use_maximum=False, first_map_only=False,
                subscribe_to_updates=False, combination_method=1, always_send_full_costmap=True,
                max_obstacle_height=2.0, min_obstacle_height=0.0, publish_voxel_map=False)
SOURCE_UNHONOURED = dict(
    expected_update_rate='an old scan does not stop the robot here', max_obstacle_height=_HEIGHT,
    observation_persistence='the newest scan alone is marked', min_obstacle_height=_HEIGHT)
SOURCE_HARMLESS = dict(expected_update_rate=0.0, observation_persistence=0.0, max_obstacle_height=2.0,
                       min_obstacle_height=0.0)


@dataclasses.dataclass(frozen=True)
class CostmapROSConfig(Checked):
    """costmap_2d's Costmap2DROS parameters: the costmap's frames, rates, window and sources (costmap_2d's
    defaults; TurtleBot3's are GLOBAL_COSTMAP and LOCAL_COSTMAP)."""
    global_frame: str = parameter('map', "the costmap's frame", frame_id)
    robot_base_frame: str = parameter('base_link', "the robot's frame", frame_id)
    update_frequency: float = parameter(5.0, 'Hz: obstacles marked and costs made anew; 0: never', non_negative, 'Hz')
    publish_frequency: float = parameter(0.0, 'Hz: the costmap published; 0: never', non_negative, 'Hz')
    transform_tolerance: float = parameter(0.3, "s: a robot pose older than this is not steered by", non_negative,
                                           's')
    static_map: bool = parameter(False, 'the map (map_topic) is its static layer; the map\'s size and '
                                        'resolution then win')
    rolling_window: bool = parameter(False, 'the costmap moves with the robot, centred on it')
    width: float = parameter(10.0, 'm (without a static map)', positive, 'm')
    height: float = parameter(10.0, 'm (without a static map)', positive, 'm')
    resolution: float = parameter(0.05, 'm per cell (without a static map)', positive, 'm')
    origin_x: float = parameter(0.0, 'm: the lower left corner of a costmap that neither rolls nor has a map',
                                None, 'm')
    origin_y: float = parameter(0.0, 'm', None, 'm')
    map_type: str = parameter('costmap', 'costmap, or voxel (taken as costmap here)', one_of('costmap', 'voxel'))
    map_topic: str = parameter('map', "the static layer's map topic", None)
    observation_sources: str = parameter('', 'the names of the sources, space separated', None)


def _laser(value):
    return None if value == 'LaserScan' else ('must be LaserScan: the costmaps here are marked from laser scans '
                                              "only (costmap_2d's default is PointCloud)")


@dataclasses.dataclass(frozen=True)
class ObservationSource(Checked):
    """One of costmap_2d's observation sources (its obstacle layer's parameters per source)."""
    topic: str = parameter('', "the scan's topic; empty: the source's name")
    sensor_frame: str = parameter('', "the sensor's frame; empty: the scan's frame_id", optional_frame_id)
    data_type: str = parameter('PointCloud', 'LaserScan (PointCloud and PointCloud2 are refused)', _laser)
    marking: bool = parameter(True, 'its hits mark obstacles')
    clearing: bool = parameter(False, 'its beams clear the cells they cross')
    obstacle_range: float = parameter(3.0, "m: hits nearer than this are marked (the costmap's)", non_negative, 'm')
    raytrace_range: float = parameter(3.5, "m: beams clear this far (the costmap's)", non_negative, 'm')
    inf_is_valid: bool = parameter(False, 'beams reading inf clear up to raytrace_range')


@dataclasses.dataclass
class CostmapSettings(object):
    """One costmap's configs: `ros` (CostmapROSConfig), `config` (CostmapConfig), `sources` ((name,
    ObservationSource), ...), `notes` (warnings beside the unhonoured parameters)."""
    name: str
    ros: CostmapROSConfig
    config: CostmapConfig
    sources: tuple
    notes: list


def footprint_of(params, name):
    """The footprint a costmap `name` is given, as costmap_2d's makeFootprintFromParams finds it: a
    `footprint` list (or string), else `robot_radius` (a circle), else None (TurtleBot3's)."""
    path = params.search(name, 'footprint')
    value = params.get(path) if path else None
    if isinstance(value, str) and value.strip() not in ('', '[]'):
        try:
            value = yaml.safe_load(value)
        except yaml.YAMLError:
            fail(path, value, 'must be a list of [x, y] points')
    if isinstance(value, str) or (isinstance(value, list) and not value):
        value = None
    if value is not None:
        return value
    path = params.search(name, 'robot_radius')
    if path is None:
        return None
    radius = params.get(path)
    problem = positive(radius) if isinstance(radius, (int, float)) and not isinstance(radius, bool) else 'a number'
    if problem:
        fail(path, radius, problem if problem.startswith('must') else 'must be a number > 0 (m)')
    return circle_footprint(float(radius))


def read_costmap(params, name, read):
    """CostmapSettings of costmap `name` ('global_costmap' or 'local_costmap') from `params`."""
    notes = []
    ros = read(CostmapROSConfig, name, params.values(CostmapROSConfig, name, DEFAULTS.get(name)),
               params.unhonoured(name, UNHONOURED, HARMLESS))
    if ros.map_type == 'voxel':
        notes.append('~%s/map_type voxel: %s' % (name, _VOXEL.split(' here: ', 1)[1]))
    values = params.values(CostmapConfig, name)
    footprint = footprint_of(params, name)
    if footprint is not None:
        values['footprint'] = footprint
    config = read(CostmapConfig, name, values, None)
    sources = []
    names = ros.observation_sources.split() if params.has(name + '/observation_sources') else [TURTLEBOT3_SOURCE[0]]
    for source in names:
        namespace = '%s/%s' % (name, source)
        defaults = dict(dict(TURTLEBOT3_SOURCE[1]) if not params.has(name + '/observation_sources') else {},
                        topic=source, inf_is_valid=config.inf_is_valid)
        for key in ('obstacle_range', 'raytrace_range'):
            found = params.search(namespace, key)
            defaults[key] = params.get(found) if found else getattr(config, key)
        if params.has(namespace) and not isinstance(params.get(namespace), dict):
            raise ParameterError('parameter ~%s = %r: must be a source\'s parameters ({data_type: LaserScan, '
                                 'topic: ...})' % (namespace, params.get(namespace)))
        values = params.values(ObservationSource, namespace, defaults)
        sources.append((source, read(ObservationSource, namespace, values,
                                     params.unhonoured(namespace, SOURCE_UNHONOURED, SOURCE_HARMLESS))))
    return CostmapSettings(name, ros, config, tuple(sources), notes)
