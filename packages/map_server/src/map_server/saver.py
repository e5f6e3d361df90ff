"""map_saver as ros-planning/navigation's (noetic): `map_saver [--occ 65] [--free 25] [-f NAME] [map:=TOPIC]`.

Saves the first map that comes on `map` as NAME.pgm and NAME.yaml (see
map_files for the format) and exits 0. Its options, messages and exit
statuses on bad use are the original's (its options parsed as its C code
parses them: atoi, so `--free x` is 0). Where the original waits for ever,
this one gives up after `~timeout` wall seconds (30; 0: for ever) with a
line saying what it waited for, and exits 1, as it does when a file cannot
be written.
"""
import sys
import threading
import time

import rospy

from tb3_common import map_files
from tb3_common.ros import lifecycle
from tb3_common.ros.map_messages import MapMessage, grid_of_message

USAGE = ('Usage: \n'
         '  map_saver -h\n'
         '  map_saver [--occ <threshold_occupied>] [--free <threshold_free>] [-f <mapname>] [ROS remapping args]')
DEFAULT_TIMEOUT = 30.0  # wall s: gmapping's first map comes after its first scans, latched; map_server's at once
POLL = 0.05  # wall s between looks at whether the map was saved


class UsageError(Exception):
    """Bad command line: `message` for stdout (usage, as puts) or stderr (an error), and the exit status."""

    def __init__(self, message, status, usage):
        super(UsageError, self).__init__(message)
        self.status, self.usage = status, usage


def _atoi(text):
    """C's atoi: optional blanks and sign, then digits; 0 if none."""
    digits = ''
    text = text.lstrip(' \t\n\v\f\r')
    sign, text = (-1, text[1:]) if text[:1] == '-' else (1, text[1:] if text[:1] == '+' else text)
    for character in text:
        if not '0' <= character <= '9':
            break
        digits += character
    return sign * int(digits) if digits else 0


def parse_arguments(arguments):
    """map_saver's SaverConfig of its arguments (ROS remappings removed), as its main() parses them;
    UsageError for -h (status 0) and for bad use (status 1)."""
    options = dict(mapname='map', threshold_occupied=65, threshold_free=25)
    names = {'-f': 'mapname', '--occ': 'threshold_occupied', '--free': 'threshold_free'}
    index = 0
    while index < len(arguments):
        argument = arguments[index]
        if argument == '-h':
            raise UsageError(USAGE, 0, True)
        if argument not in names or index + 1 >= len(arguments):
            raise UsageError(USAGE, 1, True)
        index += 1
        name = names[argument]
        options[name] = arguments[index] if name == 'mapname' else _atoi(arguments[index])
        if name == 'threshold_occupied' and not 1 <= options[name] <= 100:
            raise UsageError('threshold_occupied must be between 1 and 100', 1, False)
        if name == 'threshold_free' and not 0 <= options[name] <= 100:
            raise UsageError('threshold_free must be between 0 and 100', 1, False)
        index += 1
    try:
        return map_files.SaverConfig(**options)
    except ValueError as error:
        raise UsageError(str(error), 1, False)


class MapSaver(object):
    """Saves the first map that comes (once), and says how it went."""

    def __init__(self, config):
        self.config = config
        self.saved = self.failed = False
        self._lock = threading.Lock()
        rospy.loginfo('Waiting for the map')
        self.subscriber = rospy.Subscriber('map', MapMessage, self._on_map, queue_size=1)

    def _on_map(self, message):
        with self._lock:
            if self.saved or self.failed:
                return
            info = message.info
            rospy.loginfo('Received a %d X %d map @ %.3f m/pix', info.width, info.height, info.resolution)
            try:
                grid, values, orientation = grid_of_message(message)
            except ValueError as error:
                rospy.logwarn('map_saver: this map cannot be saved (%s): waiting for another', error)
                return
            name = self.config.mapname
            rospy.loginfo('Writing map occupancy data to %s.pgm', name)
            try:
                map_files.save_map(grid, values, self.config, orientation)
            except map_files.MapFileError as error:
                rospy.logerr('map_saver: %s', error)  # the file, then "couldn't save map file" and why
                self.failed = True
                return
            rospy.loginfo('Writing map occupancy data to %s.yaml', name)  # sic: the original's words
            rospy.loginfo('Done\n')
            self.saved = True


def main(argv=None):
    try:
        config = parse_arguments(rospy.myargv(sys.argv if argv is None else argv)[1:])
    except UsageError as error:
        if error.usage:
            print(error)
        else:
            sys.stderr.write('[ERROR] %s\n' % error)
        sys.exit(error.status)
    life = lifecycle.init_node('map_saver')
    timeout = float(rospy.get_param('~timeout', DEFAULT_TIMEOUT))
    saver = MapSaver(config)
    deadline = time.monotonic() + timeout  # wall time: a paused simulation does not stop the wait
    timed_out = False
    while not (saver.saved or saver.failed) and life.sleep(POLL):
        if timeout > 0 and time.monotonic() >= deadline:
            rospy.logerr('map_saver: no map came on %s within %g s: is a mapping node (slam_gmapping, '
                         'map_server) publishing it? (~timeout sets the wait)', saver.subscriber.resolved_name,
                         timeout)
            timed_out = True
            break
    saver.subscriber.unregister()
    life.finish()
    # Ended by Ctrl+C before a map came: 0, as the original.
    sys.exit(1 if saver.failed or timed_out else 0)
