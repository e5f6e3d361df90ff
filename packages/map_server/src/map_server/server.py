"""map_server as ros-planning/navigation's (noetic): `map_server MAP.yaml` (or, deprecated, `IMAGE RESOLUTION`).

Publishes the map latched on `map` and its MapMetaData on `map_metadata`,
answers `static_map` (nav_msgs/GetMap) with it and loads another on
`change_map` (nav_msgs/LoadMap). `~frame_id` (default map; in a namespace
NAMESPACE/map, as this project's other nodes name frames there) is the map's
frame. The node is anonymous, as the original (map_server_<pid>_<time>), so
several can serve maps on remapped topics. A map that cannot be read ends
the node at start-up with one line naming the file and the key and exit
status 255 (the original's exit(-1)); a bad `change_map` keeps the old map
and answers with LoadMap's result code for what went wrong.
"""
import os
import sys
import threading

import rospy
from nav_msgs.msg import MapMetaData, OccupancyGrid
from nav_msgs.srv import GetMap, GetMapResponse, LoadMap, LoadMapResponse

from tb3_common import map_files
from tb3_common.ros import lifecycle
from tb3_common.ros.frames import namespaced
from tb3_common.ros.map_messages import occupancy_grid

USAGE = ('\nUSAGE: map_server <map.yaml>\n'
         '  map.yaml: map description file\n'
         'DEPRECATED USAGE: map_server <map> <resolution>\n'
         '  map: image file to load\n'
         '  resolution: map resolution [meters/pixel]')
EXIT_FAILURE = 255  # exit(-1), as map_server's main
VALID_TIME_POLL = 0.01  # wall s between looks at the clock while /clock has not come


def _atof(text):
    """C's atof: the longest number at the start of `text`, else 0."""
    text = text.strip()
    for end in range(len(text), 0, -1):
        try:
            return float(text[:end])
        except ValueError:
            continue
    return 0.0


def _result_code(error):
    """LoadMap's result for a MapFileError: which part of the map was wrong."""
    if error.key is None and not os.path.isfile(error.path):
        return LoadMapResponse.RESULT_MAP_DOES_NOT_EXIST
    if error.key == 'image':
        return LoadMapResponse.RESULT_INVALID_MAP_DATA
    return LoadMapResponse.RESULT_INVALID_MAP_METADATA


class MapServer(object):
    """The served map, its latched topics and its two services."""

    def __init__(self, life, frame_id):
        self.life = life
        self.frame_id = frame_id
        self.map = None  # the OccupancyGrid served
        self._lock = threading.Lock()
        self.metadata_pub = rospy.Publisher('map_metadata', MapMetaData, queue_size=1, latch=True)
        self.map_pub = rospy.Publisher('map', OccupancyGrid, queue_size=1, latch=True)

    def advertise(self):
        rospy.Service('static_map', GetMap, self._on_static_map)
        rospy.Service('change_map', LoadMap, self._on_change_map)

    def serve(self, loaded):
        """Publishes `loaded` (a map_files.LoadedMap) as the map, stamped now."""
        rospy.loginfo('Loading map from image "%s"', loaded.metadata.image)
        self._wait_for_valid_time()
        message = occupancy_grid(loaded.grid, loaded.values, self.frame_id, rospy.Time.now())
        rospy.loginfo('Read a %d X %d map @ %.3f m/cell', message.info.width, message.info.height,
                      message.info.resolution)
        with self._lock:
            self.map = message
            self.metadata_pub.publish(message.info)
            self.map_pub.publish(message)
        return message

    def _wait_for_valid_time(self):
        """As ros::Time::waitForValid: under use_sim_time, until /clock has come."""
        while rospy.Time.now().is_zero() and self.life.sleep(VALID_TIME_POLL):
            pass

    def _on_static_map(self, _request):
        rospy.loginfo('Sending map')
        return GetMapResponse(map=self.map)

    def _on_change_map(self, request):
        try:
            message = self.serve(map_files.load_map(request.map_url))
        except map_files.MapFileError as error:
            rospy.logerr('%s', error)
            return LoadMapResponse(result=_result_code(error))
        rospy.loginfo('Changed map to %s', request.map_url)
        return LoadMapResponse(map=message, result=LoadMapResponse.RESULT_SUCCESS)


def _load(arguments):
    """The LoadedMap the command line names: a YAML, or (deprecated) an image and its resolution."""
    if len(arguments) == 1:
        return map_files.load_map(arguments[0])
    rospy.logwarn('Using deprecated map server interface. Please switch to new interface.')
    metadata = map_files.MapMetadata(arguments[0], _atof(arguments[1]), (0.0, 0.0, 0.0),
                                     rospy.get_param('~negate', 0), rospy.get_param('~occupied_thresh', 0.65),
                                     rospy.get_param('~free_thresh', 0.196))
    if not metadata.resolution > 0:
        raise map_files.MapFileError(arguments[0], None, 'the resolution %r must be > 0 (metres per pixel)'
                                     % arguments[1])
    return map_files.load_image(metadata)


def main(argv=None):
    arguments = rospy.myargv(sys.argv if argv is None else argv)[1:]
    if len(arguments) not in (1, 2):
        sys.stderr.write('[ERROR] %s\n' % USAGE)
        sys.exit(EXIT_FAILURE)
    life = lifecycle.init_node('map_server', anonymous=True)
    server = MapServer(life, rospy.get_param('~frame_id', namespaced('map', rospy.get_namespace())))
    try:
        server.serve(_load(arguments))
    except map_files.MapFileError as error:
        rospy.logerr('map_server cannot start: %s', error)
        life.request_stop('no map to serve')
        life.finish()
        sys.exit(EXIT_FAILURE)
    server.advertise()
    life.spin()
