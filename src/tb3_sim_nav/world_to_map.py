"""world_to_map WORLD -f NAME [--start X Y] [--resolution 0.05]: a world file rasterised into a map_server map.
No master needed.

The map is the world cut at the Burger's lidar height (world_map.map_of_world:
a cell is occupied if an obstacle covers any of it, free otherwise), over the
world's outline plus a margin; with --start, the map a perfect mapping run
from (X, Y) would give: what is reachable from there free, the surfaces seen
from it occupied (one cell thick, as a SLAM's map), the rest unknown. It is
written as map_saver writes maps (NAME.pgm and NAME.yaml), except that the
YAML names its image by its bare file name, so the two files can move
together (map_saver writes the path -f gave it). The maps in maps/ were made
so, each from its launch's spawn pose:

    rosrun tb3_sim_nav world_to_map turtlebot3_world -f maps/turtlebot3_world --start -2.0 -0.5
"""
import argparse
import os
import sys

from tb3_common.map_files import MapFileError, SaverConfig, save_map

from .world_file import WorldError, load_world
from .world_map import BURGER_SCAN_HEIGHT, map_of_world

WORLDS = os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..', 'worlds')


def _worlds_folder():
    try:
        import rospkg
        return os.path.join(rospkg.RosPack().get_path('tb3_sim_nav'), 'worlds')
    except Exception:  # no ROS environment: the checkout's own folder
        return os.path.normpath(WORLDS)


def _positive(text):
    value = float(text)
    if not value > 0:
        raise argparse.ArgumentTypeError('must be > 0, not %s' % text)
    return value


def main(argv=None):
    parser = argparse.ArgumentParser(prog='world_to_map', description=__doc__.split('\n')[0])
    parser.add_argument('world', help='a world by name (worlds/NAME.yaml) or the path of a world file')
    parser.add_argument('-f', dest='name', required=True, help='write NAME.pgm and NAME.yaml')
    parser.add_argument('--start', type=float, nargs=2, metavar=('X', 'Y'),
                        help='map only what is seen from the space reachable from (X, Y), as a SLAM would')
    parser.add_argument('--resolution', type=_positive, default=0.05, help='metres per cell (0.05)')
    parser.add_argument('--margin', type=float, default=0.5, help='free border around the world, m (0.5)')
    parser.add_argument('--height', type=float, default=BURGER_SCAN_HEIGHT,
                        help="the cut's height above the ground, m (the Burger's lidar: %g)" % BURGER_SCAN_HEIGHT)
    options = parser.parse_args(sys.argv[1:] if argv is None else argv)
    try:
        world = load_world(options.world, _worlds_folder())
        grid, values = map_of_world(world.obstacles, options.resolution, options.margin, options.height,
                                    options.start)
        pgm, yaml_path = save_map(grid, values, SaverConfig(mapname=options.name),
                                  image=os.path.basename(options.name) + '.pgm')
    except (WorldError, MapFileError, ValueError) as error:
        sys.stderr.write('world_to_map: %s\n' % error)
        return 1
    print('world_to_map: %s -> %s, %s: %d x %d cells at %g m from (%g, %g), %d occupied'
          % (options.world, pgm, yaml_path, grid.width, grid.height, grid.resolution, grid.origin[0],
             grid.origin[1], int((values == 100).sum())))
    return 0
