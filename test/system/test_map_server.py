"""map_server and map_saver as a user runs them (`rosrun map_server ...`), against a master of their own.

map_server serves a shipped map latched on `map` and `map_metadata` and on
`static_map`, and changes it on `change_map`; map_saver saves it back as
files byte for byte equal to the shipped ones (which are in map_saver's
format); a bad YAML and a map_saver that gets no map end non-zero with one
line saying why. This process is a rospy node (one per process: one master
for the whole file).
"""
import subprocess
import sys
import time

import numpy as np
import pytest

from tb3_common.map_files import load_map
from tb3_harness.processes import Process, start_master

from tb3_system_utils import run, wait_until

TIMEOUT = 20.0  # wall s for anything to arrive or end
pytestmark = pytest.mark.filterwarnings('ignore:notifyAll:DeprecationWarning')


@pytest.fixture(scope='module')
def node(tmp_path_factory):
    """A master (wall time: no simulator here) and this process as a rospy node."""
    folder = tmp_path_factory.mktemp('map_server')
    master = start_master(str(folder))
    try:
        import rosgraph
        import rospy
        rosgraph.Master('/map_server_test').setParam('/use_sim_time', False)
        rospy.init_node('map_server_test', anonymous=True, argv=[sys.argv[0]], disable_signals=True)
        yield folder
    finally:
        import rospy
        if rospy.core.is_initialized():
            rospy.signal_shutdown('map_server test done')
        master.stop()


@pytest.fixture(scope='module')
def served(node, repo_root):
    """map_server serving maps/turtlebot3_world.yaml, as its launch would start it."""
    process = Process('map_server', ['rosrun', 'map_server', 'map_server',
                                     str(repo_root / 'maps' / 'turtlebot3_world.yaml')], str(node))
    try:
        import rosservice
        assert wait_until(lambda: '/static_map' in (rosservice.get_service_list() or []) or not process.running(),
                          TIMEOUT), 'no static_map within %.0f s' % TIMEOUT
        assert process.running(), process.output()
        yield process
    finally:
        process.stop()


@pytest.fixture(scope='module')
def repo_root():
    from pathlib import Path
    return Path(__file__).resolve().parents[2]


def _values(message):
    return np.array(message.data, dtype=np.int8).reshape(message.info.height, message.info.width)


def test_map_server_serves_a_shipped_map_latched_and_on_static_map(served, repo_root):
    import rospy
    from nav_msgs.msg import MapMetaData, OccupancyGrid
    from nav_msgs.srv import GetMap
    truth = load_map(str(repo_root / 'maps' / 'turtlebot3_world.yaml'))
    time.sleep(1.0)  # subscribed well after map_server published: only a latched topic still delivers
    latched = rospy.wait_for_message('map', OccupancyGrid, timeout=TIMEOUT)
    metadata = rospy.wait_for_message('map_metadata', MapMetaData, timeout=TIMEOUT)
    answered = rospy.ServiceProxy('static_map', GetMap)().map
    for message in (latched, answered):
        assert message.header.frame_id == 'map'
        assert (message.info.width, message.info.height) == (truth.grid.width, truth.grid.height)
        assert message.info.resolution == pytest.approx(0.05)
        assert (message.info.origin.position.x, message.info.origin.position.y) == truth.grid.origin[:2]
        assert message.info.origin.orientation.w == 1.0
        assert np.array_equal(_values(message), truth.values)
    assert metadata == latched.info and not latched.header.stamp.is_zero()


def test_map_saver_saves_it_back_byte_for_byte(served, repo_root, tmp_path):
    # As a user types it in the folder the map goes to: the YAML names the image as -f gave it.
    saver = subprocess.run(['rosrun', 'map_server', 'map_saver', '-f', 'turtlebot3_world'], cwd=str(tmp_path),
                           stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True, timeout=TIMEOUT)
    print('MEASURED map_saver output:\n' + saver.stdout)
    assert saver.returncode == 0, saver.stdout
    grid = load_map(str(repo_root / 'maps' / 'turtlebot3_world.yaml')).grid
    for line in ('Waiting for the map', 'Received a %d X %d map @ 0.050 m/pix' % (grid.width, grid.height),
                 'Writing map occupancy data to turtlebot3_world.pgm', 'Done'):
        assert line in saver.stdout
    for suffix in ('.pgm', '.yaml'):
        saved = (tmp_path / ('turtlebot3_world' + suffix)).read_bytes()
        assert saved == (repo_root / 'maps' / ('turtlebot3_world' + suffix)).read_bytes(), suffix


def test_map_saver_that_cannot_write_ends_non_zero_with_one_line(served, tmp_path):
    ended = run(['rosrun', 'map_server', 'map_saver', '-f', str(tmp_path / 'no_such_folder' / 'map')], TIMEOUT)
    assert ended.returncode == 1
    assert [line for line in ended.stdout.splitlines()
            if "no_such_folder/map.pgm: couldn't save map file: No such file or directory" in line]


def test_change_map_serves_another_and_refuses_a_missing_one(served, repo_root):
    import rospy
    from nav_msgs.msg import OccupancyGrid
    from nav_msgs.srv import LoadMap, LoadMapResponse
    change = rospy.ServiceProxy('change_map', LoadMap)
    received = []
    subscriber = rospy.Subscriber('map', OccupancyGrid, received.append)
    try:
        answer = change(str(repo_root / 'maps' / 'turtlebot3_stage_1.yaml'))
        assert answer.result == LoadMapResponse.RESULT_SUCCESS and answer.map.info.width == 102
        assert wait_until(lambda: any(m.info.width == 102 for m in received), TIMEOUT)
        missing = change('/nonexistent/map.yaml')
        assert missing.result == LoadMapResponse.RESULT_MAP_DOES_NOT_EXIST
    finally:
        subscriber.unregister()
        change(str(repo_root / 'maps' / 'turtlebot3_world.yaml'))  # as the other tests expect


def test_a_bad_yaml_ends_map_server_non_zero_with_one_line(node, tmp_path):
    bad = tmp_path / 'no_resolution.yaml'
    bad.write_text('image: map.pgm\norigin: [0, 0, 0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n')
    ended = run(['rosrun', 'map_server', 'map_server', str(bad)], TIMEOUT)
    print('MEASURED bad YAML: exit %r, output: %s' % (ended.returncode, ended.stdout.strip()))
    assert ended.returncode not in (0, None)
    lines = [line for line in ended.stdout.splitlines() if "%s: key 'resolution': missing" % bad in line]
    assert len(lines) == 1 and 'ERROR' in lines[0]


def test_map_saver_without_a_map_ends_non_zero_with_one_line(node, tmp_path):
    ended = run(['rosrun', 'map_server', 'map_saver', '-f', str(tmp_path / 'none'), 'map:=/no_map_here',
                 '_timeout:=2'], TIMEOUT)
    print('MEASURED map_saver without a map: exit %r, output: %s' % (ended.returncode, ended.stdout.strip()))
    assert ended.returncode == 1
    assert [line for line in ended.stdout.splitlines() if 'no map came on /no_map_here within 2 s' in line]
    assert not (tmp_path / 'none.pgm').exists()
    refused = run(['rosrun', 'map_server', 'map_saver', '--occ', '0'], TIMEOUT)
    assert refused.returncode == 1 and 'threshold_occupied must be between 1 and 100' in refused.stdout


def test_the_deprecated_image_and_resolution_form_serves_the_image_at_origin_zero(node, repo_root):
    import rospy
    from nav_msgs.msg import OccupancyGrid
    truth = load_map(str(repo_root / 'maps' / 'turtlebot3_world.yaml'))
    process = Process('map_server_deprecated', [
        'rosrun', 'map_server', 'map_server', str(repo_root / 'maps' / 'turtlebot3_world.pgm'), '0.1',
        'map:=/old_map', 'map_metadata:=/old_map_metadata', 'static_map:=/old_static_map',
        'change_map:=/old_change_map'], str(node))
    try:
        message = rospy.wait_for_message('/old_map', OccupancyGrid, timeout=TIMEOUT)
        assert message.info.resolution == pytest.approx(0.1)
        assert (message.info.origin.position.x, message.info.origin.position.y) == (0.0, 0.0)
        assert np.array_equal(_values(message), truth.values)
        assert wait_until(lambda: 'Using deprecated map server interface' in process.output(), TIMEOUT)
    finally:
        process.stop()
