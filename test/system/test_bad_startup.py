"""Bad start-up configurations end `roslaunch` with an error that says what is wrong.

Against a roscore (one for all, on a free loopback port), each case runs
`roslaunch tb3_sim_bringup LAUNCH ARGS` as the user would. The simulator node
is required="true": when it refuses to start, roslaunch must end within 60 s,
an error line of its output (not roslaunch's listing of the parameters) must
name the parameter or file and the value, and the failure must carry a
non-zero exit status: the simulator node's (2, which roslaunch reports; Debian's
roslaunch 1.15 itself exits 0 when a required node dies) or roslaunch's own,
when it cannot even read its launch file.
"""
import re

import pytest

from tb3_system_utils import wait_until

EXIT_WITHIN = 60.0      # wall s
ERROR_LINE = re.compile(r'FATAL|ERROR|RLException|cannot start|[Ii]nvalid|No such file|does not exist')

MALFORMED_WORLD = """\
# a box needs three edge lengths
obstacles:
  - box: {size: [1.0, 0.1], position: [1.0, 0.0]}
"""


def cases(tmp_path):
    malformed = tmp_path / 'malformed_world.yaml'
    malformed.write_text(MALFORMED_WORLD)
    return {
        # name: (launch file, arguments, what an error line must contain[, private
        # parameters of /tb3_sim set before roslaunch, as the README says to])
        'negative_real_time_factor': ('tb3_empty_world.launch', ['real_time_factor:=-1'],
                                      ['real_time_factor', '-1']),
        'unknown_model': ('tb3_empty_world.launch', ['model:=no_such_model'],
                          ['no_such_model', 'the models are burger, waffle, waffle_pi']),
        'missing_world_file': ('tb3_empty_world.launch', ['world:=/nonexistent.yaml'],
                               ['world', '/nonexistent.yaml']),
        'malformed_world_file': ('tb3_empty_world.launch', ['world:=%s' % malformed],
                                 [str(malformed), '[1.0, 0.1]']),
        # (0, 0) is the centre of the central pillar of turtlebot3_world.
        'spawn_inside_central_pillar': ('tb3_world.launch', ['x_pos:=0.0', 'y_pos:=0.0'],
                                        ['x_pos', '(0.00, 0.00)']),
        'real_time_factor_not_a_number': ('tb3_empty_world.launch', ['real_time_factor:=fast'],
                                          ['real_time_factor', 'fast']),
        'camera_rate_above_physics_rate': ('tb3_empty_world.launch', ['model:=waffle_pi'],
                                           ['camera_rate', '500'], {'/tb3_sim/camera_rate': 500.0}),
    }


CASES = ['negative_real_time_factor', 'unknown_model', 'missing_world_file', 'malformed_world_file',
         'spawn_inside_central_pillar', 'real_time_factor_not_a_number', 'camera_rate_above_physics_rate']


@pytest.mark.parametrize('case', CASES)
def test_start_up_fails_nonzero_naming_parameter_or_file_and_value(case, shared_master, processes, tmp_path):
    launch, arguments, expected, parameters = (cases(tmp_path)[case] + ({},))[:4]
    import rosgraph
    for name, value in parameters.items():
        rosgraph.Master('/tb3_bad_startup_test').setParam(name, value)
    launched = processes.start('roslaunch_' + case, ['roslaunch', 'tb3_sim_bringup', launch] + arguments)
    ended = wait_until(lambda: not launched.running(), EXIT_WITHIN)
    with open(launched.log, errors='replace') as log:
        output = log.read()
    errors = [line for line in output.splitlines() if ERROR_LINE.search(line)]
    node_exit = re.findall(r'process has died \[pid \d+, exit code (-?\d+)', output)
    print('MEASURED bad_startup %s: roslaunch exit %r, node exit %s, error lines: %s'
          % (case, launched.popen.returncode, node_exit, errors[:3]))
    assert ended, 'roslaunch %s %s still running after %.0f s; output:\n%s' % (
        launch, ' '.join(arguments), EXIT_WITHIN, output[-3000:])
    assert any(all(text in line for text in expected) for line in errors), \
        'no error line names %s; error lines: %s' % (expected, errors)
    failed_with = [int(code) for code in node_exit if int(code) != 0] + \
        ([launched.popen.returncode] if launched.popen.returncode != 0 else [])
    assert failed_with, \
        'roslaunch %s %s: neither the simulator node (exit codes reported: %s) nor roslaunch (%s) ' \
        'ended with a non-zero status; error lines: %s' % (
            launch, ' '.join(arguments), node_exit or 'none', launched.popen.returncode, errors[:3])
