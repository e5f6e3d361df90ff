"""Drive a TurtleBot3 from the keyboard, as ROBOTIS' turtlebot3_teleop_key does.

    roslaunch turtlebot3_teleop turtlebot3_teleop_key.launch   # ROBOTIS' e-manual
    rosrun turtlebot3_teleop turtlebot3_teleop_key             # model from TURTLEBOT3_MODEL, else burger
    rosrun turtlebot3_teleop turtlebot3_teleop_key _model:=waffle
    roslaunch tb3_sim_bringup tb3_teleop_key.launch            # the tutorial's names for the same node
    rosrun tb3_sim_nav tb3_teleop_key

Each key changes a *target* speed (turtlebot3_teleop.keys): w/x forward
speed up/down by 0.01 m/s, a/d turn more to the left/right by 0.1 rad/s, s
or space stop. The speed sent follows the target in half steps, and goes out
as a geometry_msgs/Twist on cmd_vel at once after each key, and otherwise
every 0.1 s (about 10 times a second).

The model comes from ~model, else `model` in the node's namespace (where
ROBOTIS' launch file sets it), else $TURTLEBOT3_MODEL, else burger.

Ctrl+C, closing the terminal, `kill` (SIGTERM), `rosnode kill` or the end of
the roslaunch that started it make it publish a stop, put the terminal back as
it was, and exit.
"""
import os
import select
import sys
import termios
import time
import tty

import rospy
from geometry_msgs.msg import Twist

from tb3_common.ros import lifecycle, params

from .keys import Speeds, TeleopConfig

NODE = 'turtlebot3_teleop'
KEY_WAIT = 0.1        # s to wait for a key before publishing again anyway
CONNECT_WAIT = 1.0    # s to wait for a subscriber before publishing the final stop
SEND_WAIT = 0.2       # s for rospy to send the final stop before we shut down
BANNER_EVERY = 20     # show the keys again after this many speed keys

BANNER = """
Drive your TurtleBot3 ({model}: at most {linear:.2f} m/s and {angular:.2f} rad/s)
        w
    a   s   d
        x
  w / x      forward speed up / down by 0.01 m/s
  a / d      turn more to the left / right by 0.1 rad/s
  s, space   stop
  Ctrl+C     stop the robot and quit
"""


def show(text):
    """Print text; if the terminal is already closed, there is no one to tell."""
    try:
        print(text, flush=True)
    except OSError:
        pass


def read_key(terminal):
    """The key typed within KEY_WAIT s, '' if none, None if the terminal is gone."""
    ready, _, _ = select.select([terminal], [], [], KEY_WAIT)
    if not ready:
        return ''
    try:
        data = os.read(terminal, 1)
    except OSError:      # the terminal was closed under us
        return None
    if not data:         # end of input: the terminal was closed
        return None
    return data.decode('ascii', 'replace')


def read_config():
    """The TeleopConfig: ~model, else ROBOTIS' `model`, else $TURTLEBOT3_MODEL, else burger (with a note)."""
    if rospy.has_param('~model'):
        return params.read_or_exit(NODE, TeleopConfig)
    model = str(rospy.get_param('model', '')) or os.environ.get('TURTLEBOT3_MODEL', '')
    if not model:
        show('No ~model parameter and TURTLEBOT3_MODEL is not set: using burger.')
        model = 'burger'
    return params.read_or_exit(NODE, TeleopConfig, overrides={'model': model})


def drive(terminal, publisher, model, life):
    """Read keys and publish speeds until asked to quit."""
    speeds = Speeds(model)
    banner = BANNER.format(model=model, linear=speeds.max_linear, angular=speeds.max_angular)
    speed_keys = 0
    show(banner)
    while not life.stopping:
        key = read_key(terminal)
        if key is None:
            break
        pressed = speeds.press(key)
        if pressed:
            show('target: linear %.2f m/s, angular %.2f rad/s' % (speeds.target_linear, speeds.target_angular))
        if pressed == 'speed':
            speed_keys += 1
            if speed_keys % BANNER_EVERY == 0:
                show(banner)
        twist = Twist()
        twist.linear.x, twist.angular.z = speeds.step()
        publisher.publish(twist)


def stop_robot(publisher):
    """Publish a zero Twist, and give it the time to reach the robot."""
    if rospy.is_shutdown():   # the node was shut down from outside: cannot publish
        return
    # A subscriber that has only just found us is not connected yet: a
    # message published now would not reach it. Wait a little for one.
    deadline = time.monotonic() + CONNECT_WAIT
    while publisher.get_num_connections() == 0 and time.monotonic() < deadline:
        time.sleep(0.01)
    publisher.publish(Twist())   # all fields zero
    # rospy sends from a thread of its own, and shutting down closes the
    # connections: let that thread send the stop first.
    time.sleep(SEND_WAIT)
    show('Stopped: published a zero Twist on cmd_vel.')


def restore_terminal(terminal, settings):
    try:
        termios.tcsetattr(terminal, termios.TCSADRAIN, settings)
    except termios.error:   # the terminal is gone: nothing to restore
        pass


def main():
    # Keys come from a terminal; anything else (a file, a pipe) cannot work.
    if not sys.stdin.isatty():
        print('%s: standard input is not a terminal; run it in a terminal of its own'
              % os.path.basename(sys.argv[0]), file=sys.stderr)
        return 1

    # Ctrl+C, a closed terminal (SIGHUP), SIGTERM, rosnode kill or a dead
    # roslaunch only ask the loop to end (lifecycle), so that rospy does not
    # shut down before we have published the stop.
    life = lifecycle.init_node(NODE)
    config = read_config()   # an unknown model ends the node here, naming the three
    publisher = rospy.Publisher('cmd_vel', Twist, queue_size=10)

    # cbreak mode: each key arrives as it is pressed, without Enter and
    # without being echoed; Ctrl+C still sends SIGINT.
    terminal = sys.stdin.fileno()
    settings = termios.tcgetattr(terminal)
    tty.setcbreak(terminal)
    try:
        drive(terminal, publisher, config.model, life)
    finally:
        restore_terminal(terminal, settings)
        stop_robot(publisher)
        life.finish()
    return 0
