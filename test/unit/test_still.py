"""Still means still: a stopped robot stays where it stopped (no ROS, the Simulation core).

Many stops, in both profiles: after turns both ways, straight runs both ways
and an arc, stopped by a zero command or by the command timeout, with the
last command landing at different step offsets (what a busy core or another
real-time factor changes). One second after the wheels stop, ground truth
reads below 1 mm/s and 0.001 rad/s, and stays there for a minute of sim time.
"""
import math

import pytest

from tb3_sim_nav.frames import IDENTITY
from tb3_sim_nav.params import PARAMETERS, resolve
from tb3_sim_nav.robot_model import load_model
from tb3_sim_nav.simulation import build

RATE = 100           # physics steps per sim second
STILL_SPEED = 0.001  # m/s
STILL_TURN = 0.001   # rad/s
AFTER_STOP = 1.0     # sim s from the wheels' stop to the first check
WATCH = 60.0         # sim s of checks

MANOEUVRES = {       # (v m/s, w rad/s, sim s): calibrate_angular's full turn, the tutorial's legs, an arc
    'turn_left': (0.0, 0.5, 2 * math.pi / 0.5),
    'turn_right': (0.0, -0.5, 2 * math.pi / 0.5),
    'fast_turn': (0.0, 2.0, 1.3),
    'forward': (0.2, 0.0, 5.0),
    'backward': (-0.2, 0.0, 5.0),
    'arc': (0.1, 0.5, 3.0),
}


def stop_and_watch(burger_urdf, profile, manoeuvre, stop, offset):
    """Worst true (|v|, |w|) from AFTER_STOP after the wheels stopped, for WATCH sim s."""
    overrides = dict(model=str(burger_urdf), profile=profile, seed=3)
    if stop == 'timeout':
        overrides['cmd_vel_timeout'] = 0.5
    assert set(overrides) <= {parameter.name for parameter in PARAMETERS}
    config = resolve(lambda name, default: overrides.get(name, default))
    sim = build(config, (), [('', load_model(str(burger_urdf)), IDENTITY)])
    try:
        robot = sim.robots['']
        v, w, seconds = MANOEUVRES[manoeuvre]
        for step in range(int(seconds * RATE) + offset):
            if step % 10 == 0:  # `rostopic pub -r 10`
                robot.command(v, w, sim.now_ns)
            sim.step()
        if stop == 'zero':
            robot.command(0.0, 0.0, sim.now_ns)
        steps = 0
        while robot.drive.speeds != (0.0, 0.0):
            sim.step()
            steps += 1
            assert steps < 5 * RATE, 'the wheels did not stop within 5 s of sim time'
        for _ in range(int(AFTER_STOP * RATE)):
            sim.step()
        worst = [0.0, 0.0]
        for _ in range(int(WATCH * RATE)):
            sim.step()
            _, (linear, angular) = robot.truth()
            worst = [max(worst[0], math.hypot(linear[0], linear[1])), max(worst[1], abs(angular[2]))]
        return worst
    finally:
        sim.close()


@pytest.mark.parametrize('profile', ['gazebo', 'realistic'])
@pytest.mark.parametrize('manoeuvre', sorted(MANOEUVRES))
@pytest.mark.parametrize('stop', ['zero', 'timeout'])
def test_a_stopped_robot_stays_still_for_a_minute(burger_urdf, profile, manoeuvre, stop):
    # Three offsets of the last command against the 10 Hz commands: the robot
    # that began to spin in about one stop in four did so for some of them.
    for offset in (0, 3, 7):
        speed, turn = stop_and_watch(burger_urdf, profile, manoeuvre, stop, offset)
        assert speed < STILL_SPEED and turn < STILL_TURN, (
            '%s, %s, stopped by %s, last command %d steps late: up to %.5f m/s and %.5f rad/s '
            'from %g s after the wheels stopped' % (profile, manoeuvre, stop, offset, speed, turn, AFTER_STOP))
