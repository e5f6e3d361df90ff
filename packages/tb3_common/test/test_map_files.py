"""map_server's files (tb3_common.map_files): written byte for byte as map_saver writes them and read
back, both ways; the shipped maps and ROS by Example's; map_saver's options, command line and errors; the
map messages. How the loader reads an image, and its errors naming the file and the key, are
test_map_loading.py's."""
import hashlib
import math
import os
import shutil

import numpy as np
import pytest
from PIL import Image

from tb3_common import map_files, pose2d
from tb3_common.grid import Grid
from tb3_common.map_files import MapFileError, SaverConfig
from tb3_common.pose2d import quaternion_of_yaw
from tb3_harness import ROOT as REPO

FIXTURE = REPO / 'test' / 'data' / 'map_saver'
RBX1 = REPO / 'maps' / 'rbx1'
# The fixture's picture (test/data/map_saver/README.md), its first row the highest y.
FIXTURE_ROWS = ['##########', '#........?', '#.??.....?', '#....##..?', '#........#', '#####....#']
SHIPPED = ['turtlebot3_world', 'turtlebot3_house', 'turtlebot3_stage_1', 'turtlebot3_stage_2',
           'turtlebot3_stage_3', 'turtlebot3_stage_4']


def _values(rows):
    """int8 values [iy, ix] of a picture whose first row is the highest y."""
    code = {'#': 100, '.': 0, '?': -1}
    return np.array([[code[c] for c in row] for row in reversed(rows)], dtype=np.int8)


# --- the format, both ways ---------------------------------------------------------
def test_a_map_written_as_map_saver_writes_one_loads_to_its_grid():
    loaded = map_files.load_map(str(FIXTURE / 'fixture.yaml'))
    assert loaded.grid == Grid(0.05, 10, 6, (-0.25, -0.1, 0.0))
    assert loaded.values.dtype == np.int8
    assert np.array_equal(loaded.values, _values(FIXTURE_ROWS))
    # Cell (0, 0) is the image's bottom-left pixel: occupied, at the origin's corner.
    assert loaded.values[0, 0] == 100 and loaded.values[0, 5] == 0 and loaded.values[4, 9] == -1
    assert loaded.metadata.image == str(FIXTURE / 'fixture.pgm')


def test_saving_that_grid_writes_map_savers_files_byte_for_byte(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # as `map_saver -f fixture` run in a folder
    loaded = map_files.load_map(str(FIXTURE / 'fixture.yaml'))
    pgm, yaml_path = map_files.save_map(loaded.grid, loaded.values, SaverConfig(mapname='fixture'))
    assert (pgm, yaml_path) == ('fixture.pgm', 'fixture.yaml')
    assert (tmp_path / 'fixture.pgm').read_bytes() == (FIXTURE / 'fixture.pgm').read_bytes()
    assert (tmp_path / 'fixture.yaml').read_bytes() == (FIXTURE / 'fixture.yaml').read_bytes()


@pytest.mark.parametrize('name', SHIPPED + ['rbx1/test_map', 'rbx1/blank_map'])
def test_maps_round_trip_load_save_load(name, tmp_path):
    """File -> grid -> file -> the same grid; and for map_saver's own files the same bytes."""
    source = REPO / 'maps' / (name + '.yaml')
    first = map_files.load_map(str(source))
    base = tmp_path / os.path.basename(name)
    map_files.save_map(first.grid, first.values, SaverConfig(mapname=str(base)), image=base.name + '.pgm')
    second = map_files.load_map(str(base) + '.yaml')
    assert second.grid == first.grid
    assert np.array_equal(second.values, first.values)
    if not name.startswith('rbx1'):  # ours were written by map_saver's format; the book's by GIMP
        assert (tmp_path / (base.name + '.pgm')).read_bytes() == source.with_suffix('.pgm').read_bytes()
        assert (tmp_path / (base.name + '.yaml')).read_bytes() == source.read_bytes()


def test_grid_to_files_to_grid_keeps_every_value_map_saver_can_tell_apart(tmp_path):
    rng = np.random.default_rng(3)
    values = rng.integers(-1, 101, size=(37, 53)).astype(np.int8)
    grid = Grid(0.025, 53, 37, (-1.5, 2.25, 0.0))
    map_files.save_map(grid, values, SaverConfig(mapname=str(tmp_path / 'r')))
    loaded = map_files.load_map(str(tmp_path / 'r.yaml'))
    # map_saver's three classes: 0..25 free, >= 65 occupied, the rest (and -1) unknown.
    expected = np.where(values >= 65, 100, np.where((values >= 0) & (values <= 25), 0, -1))
    assert loaded.grid == grid
    assert np.array_equal(loaded.values, expected)


def test_pgm_pixels_follow_occ_and_free_and_the_top_row_is_the_highest_y():
    values = np.array([[-1, 0, 10, 25, 26, 64, 65, 100], [0, 0, 0, 0, 0, 0, 0, 0]], dtype=np.int8)
    data = map_files.pgm_bytes(values, 0.05)
    header = b'P5\n# CREATOR: map_saver.cpp 0.050 m/pix\n8 2\n255\n'
    assert data[:len(header)] == header
    assert list(data[len(header):len(header) + 8]) == [254] * 8  # row 1 (higher y) comes first
    assert list(data[len(header) + 8:]) == [205, 254, 254, 254, 205, 205, 0, 0]
    # --occ 50 --free 10: 26 and 64 change class.
    custom = map_files.pgm_bytes(values, 0.05, threshold_occupied=50, threshold_free=10)
    assert list(custom[len(header) + 8:]) == [205, 254, 254, 205, 205, 0, 0, 0]


@pytest.mark.parametrize('resolution, printed', [(0.05, '0.050'), (0.1, '0.100'), (0.0125, '0.013'),
                                                 (1.0, '1.000')])
def test_pgm_header_prints_the_resolution_with_three_decimals(resolution, printed):
    data = map_files.pgm_bytes(np.zeros((1, 1), dtype=np.int8), resolution)
    assert data.startswith(('P5\n# CREATOR: map_saver.cpp %s m/pix\n1 1\n255\n' % printed).encode())


def test_yaml_text_is_map_savers_printf():
    text = map_files.yaml_text('/home/learner/map.pgm', 0.05, (-10.0, -10.0), (0.0, 0.0, 0.0, 1.0))
    assert text == ('image: /home/learner/map.pgm\nresolution: 0.050000\norigin: [-10.000000, -10.000000, '
                    '0.000000]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n\n')


def test_yaml_image_is_the_f_argument_as_given_and_the_thresholds_are_always_the_defaults(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / 'sub').mkdir()
    grid = Grid(0.1, 2, 2, (0.5, -0.25, 0.0))
    map_files.save_map(grid, np.zeros((2, 2), dtype=np.int8),
                       SaverConfig(threshold_occupied=90, threshold_free=5, mapname='sub/my_map'))
    text = (tmp_path / 'sub' / 'my_map.yaml').read_text()
    assert text.split('\n')[0] == 'image: sub/my_map.pgm'
    assert 'resolution: 0.100000\norigin: [0.500000, -0.250000, 0.000000]\n' in text
    assert text.endswith('negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n\n')


def test_the_yaml_yaw_is_tf2s_yaw_of_the_origin_quaternion():
    from tf.transformations import euler_from_quaternion, quaternion_from_euler
    for roll, pitch, yaw in [(0.0, 0.0, 0.7), (0.0, 0.0, -3.1), (0.3, -0.2, 2.5), (0.0, 0.0, math.pi / 2)]:
        q = quaternion_from_euler(roll, pitch, yaw)
        assert pose2d.yaw_of_quaternion(*q) == pytest.approx(euler_from_quaternion(q)[2], abs=1e-12)
        # Not normalised: tf2's Matrix3x3 scales by 2 / |q|^2.
        assert pose2d.yaw_of_quaternion(*(2.0 * q)) == pytest.approx(yaw, abs=1e-12)
    text = map_files.yaml_text('m.pgm', 0.05, (1.0, 2.0), quaternion_of_yaw(0.785398))
    assert 'origin: [1.000000, 2.000000, 0.785398]' in text


def test_the_shipped_maps_name_their_image_by_its_bare_name_so_they_move_with_their_folder(tmp_path):
    for name in SHIPPED:
        shutil.copy(str(REPO / 'maps' / (name + '.yaml')), str(tmp_path))
        shutil.copy(str(REPO / 'maps' / (name + '.pgm')), str(tmp_path))
        assert (REPO / 'maps' / (name + '.yaml')).read_text().startswith('image: %s.pgm\n' % name)
        assert map_files.load_map(str(tmp_path / (name + '.yaml'))).values.size > 0


# --- ROS by Example's maps ---------------------------------------------------------
# sha256 of pirobot/rbx1's files (indigo-devel, rbx1_nav/maps/) and of the note that came with them.
RBX1_SHA256 = {
    'README.md': '34855bf842d518a6e6e05f959578e79980dec5ce50dc9d4e0c63d45206819d30',
    'blank_map.pgm': '143943889a9af4dde127f73759ae94aabab07359486f6e168b1760cb8739d430',
    'blank_map.yaml': '8b5e2910cd68987e13974618aa51820fedffe7c44430c94d6bfc35361d904e62',
    'test_map.pgm': '251e0ce358fb7bb6b01ac15972a429bba43318af6950650ca5d88c8dde783367',
    'test_map.yaml': 'c6c3d328b1ed72a5fcd341c7547c15966d41dc09fe80d912f16557159643a65a',
}


def test_rbx1_maps_are_the_books_unchanged_copies_with_their_attribution():
    assert sorted(os.listdir(str(RBX1))) == sorted(RBX1_SHA256)
    for name, digest in RBX1_SHA256.items():
        assert hashlib.sha256((RBX1 / name).read_bytes()).hexdigest() == digest, name
    assert 'pirobot/rbx1' in (RBX1 / 'README.md').read_text()


def test_rbx1_test_map_loads_as_the_book_gives_it():
    loaded = map_files.load_map(str(RBX1 / 'test_map.yaml'))
    assert loaded.grid == Grid(0.05, 576, 544, (-13.8, -12.2, 0.0))
    assert loaded.metadata.occupied_thresh == 0.9
    pixels = np.asarray(Image.open(str(RBX1 / 'test_map.pgm')))  # PIL, another reader
    # Its pixels are 0, 205, 254 and a few 218, 242, 255: p = (255 - v) / 255 against 0.9 and 0.196.
    expected = np.where(pixels == 0, 100, np.where(pixels == 205, -1, 0))[::-1]
    assert np.array_equal(loaded.values, expected)
    assert (loaded.values == 100).sum() == (pixels == 0).sum() > 2000


def test_rbx1_blank_map_is_all_free():
    loaded = map_files.load_map(str(RBX1 / 'blank_map.yaml'))
    assert loaded.grid == Grid(0.01, 600, 600, (-2.5, -2.5, 0.0))
    assert (loaded.values == 0).all()


# --- map_saver's errors: the file it cannot write, its options ----------------------------------
def test_a_map_that_cannot_be_written_is_named(tmp_path):
    with pytest.raises(MapFileError, match="no_such_folder/m.pgm: couldn't save map file"):
        map_files.save_map(Grid(0.05, 1, 1), np.zeros((1, 1), np.int8),
                           SaverConfig(mapname=str(tmp_path / 'no_such_folder' / 'm')))


@pytest.mark.parametrize('options, message', [
    (dict(threshold_occupied=0), 'threshold_occupied must be between 1 and 100'),
    (dict(threshold_occupied=101), 'threshold_occupied must be between 1 and 100'),
    (dict(threshold_free=-1), 'threshold_free must be between 0 and 100'),
    (dict(threshold_occupied=30, threshold_free=30), 'threshold_free must be smaller than threshold_occupied'),
])
def test_saver_options_are_checked_as_map_saver_checks_them(options, message):
    with pytest.raises(ValueError, match='^%s$' % message):
        SaverConfig(**options)


# --- the command lines and messages of map_saver and map_server (no master needed) ------------
@pytest.mark.parametrize('argv, expected', [
    ([], SaverConfig()),
    (['-f', '/home/learner/map'], SaverConfig(mapname='/home/learner/map')),
    (['--occ', '90', '--free', '10', '-f', 'x'], SaverConfig(90, 10, 'x')),
    (['--free', 'lots'], SaverConfig(threshold_free=0)),  # atoi: no digits read 0, as in C
    (['--occ', '70%'], SaverConfig(threshold_occupied=70)),
])
def test_map_saver_parses_its_options_as_its_main_does(argv, expected):
    from map_server.saver import parse_arguments
    assert parse_arguments(argv) == expected


@pytest.mark.parametrize('argv, status, message', [
    (['-h'], 0, 'Usage: \n  map_saver -h\n'), (['-f'], 1, 'Usage: '), (['--occ'], 1, 'Usage: '),
    (['--map', 'x'], 1, 'Usage: '), (['extra'], 1, 'Usage: '),
    (['--occ', '0'], 1, 'threshold_occupied must be between 1 and 100'),
    (['--free', '101'], 1, 'threshold_free must be between 0 and 100'),
    (['--occ', '20'], 1, 'threshold_free must be smaller than threshold_occupied'),
])
def test_map_saver_refuses_bad_use_with_its_messages_and_statuses(argv, status, message):
    from map_server.saver import UsageError, parse_arguments
    with pytest.raises(UsageError) as error:
        parse_arguments(argv)
    assert error.value.status == status and str(error.value).startswith(message)


def test_map_messages_carry_the_grid_and_its_values_both_ways():
    from io import BytesIO

    import rospy
    from nav_msgs.msg import OccupancyGrid

    from tb3_common.ros.map_messages import MapMessage, grid_of_message, occupancy_grid
    grid = Grid(0.05, 4, 3, (-1.0, 2.0, 0.5))
    values = np.arange(12, dtype=np.int8).reshape(3, 4) - 1
    message = occupancy_grid(grid, values, 'map', rospy.Time(7, 5))
    assert message.info.width == 4 and message.info.height == 3 and message.data[:2] == [-1, 0]
    assert message.info.origin.orientation.z == pytest.approx(math.sin(0.25))
    buffer = BytesIO()
    message.serialize(buffer)
    received = OccupancyGrid().deserialize(buffer.getvalue())
    back, back_values, orientation = grid_of_message(received)
    assert back.width == 4 and back.height == 3 and back.origin[:2] == (-1.0, 2.0)
    assert back.origin[2] == pytest.approx(0.5) and back.resolution == pytest.approx(0.05)
    assert np.array_equal(back_values, values) and received.header.frame_id == 'map'
    # As the nodes' subscribers read it: the data an array straight from the bytes, the same values.
    received = MapMessage().deserialize(buffer.getvalue())
    assert isinstance(received.data, np.ndarray) and received._md5sum == OccupancyGrid._md5sum
    back, back_values, _ = grid_of_message(received)
    assert back.origin[:2] == (-1.0, 2.0) and np.array_equal(back_values, values)
