"""The least a simulator in python can cost at factor 1 here: a loop that
sleeps to each tick of 1 / physics_rate and publishes /clock, with (--physics)
or without a pybullet step of the Burger; nothing else. `make bench` measures
its CPU as it does the simulator's, for scale.

    python3 tools/clock_floor.py [--physics]   (inside `source setup.bash`)
"""
import argparse
import os

import rospy
from rosgraph_msgs.msg import Clock

from tb3_sim_nav.frames import IDENTITY
from tb3_sim_nav.pacing import Pacer
from tb3_sim_nav.ros.publishers import Publishers
from tb3_sim_nav.ros.rospy_internals import stop_following_clock
from tb3_sim_nav.throttle import Throttle
from tb3_sim_nav.world import World

HERE = os.path.dirname(os.path.abspath(__file__))

PHYSICS_RATE = 100.0  # Hz, the simulator's default


def main():
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--physics', action='store_true', help='also step a pybullet Burger each tick')
    args = parser.parse_args(rospy.myargv()[1:])
    rospy.init_node('tb3_clock_floor')
    stop_following_clock()
    world = World(time_step=1.0 / PHYSICS_RATE) if args.physics else None
    if world:
        with open(os.path.join(HERE, '..', 'urdf', 'turtlebot3_burger.urdf')) as urdf:
            world.add_robot(urdf.read(), IDENTITY)
    clock = Publishers(Throttle(10.0)).advertise('clock', Clock)
    pacer = Pacer(1.0)
    steps = 0
    while not rospy.is_shutdown():
        steps += 1
        pacer.wait_until(steps / PHYSICS_RATE)
        if world:
            world.step()
        clock.publish(Clock(clock=rospy.Time(*divmod(steps * int(1e9 / PHYSICS_RATE), 1000000000))))


if __name__ == '__main__':
    main()
