"""A launch file written for the real amcl and move_base runs unchanged (issue 29).

`roslaunch tb3_sim_bringup tb3_world.launch real_time_factor:=0`, then a
launch file as the ROS wiki's navigation tutorial (RobotSetup) writes one,
with its four param files loaded as it loads them: map_server on the
shipped map of turtlebot3_world, amcl with a few of amcl_diff.launch's
values, move_base with base_local_planner/TrajectoryPlannerROS by its own
parameter names, `robot_radius` instead of a footprint, frames written
`/map`, `/odom`, `/base_footprint`. Then what a learner does: rviz's 2D
Pose Estimate at the spawn pose, two goals around the pillars through the
move_base action, each SUCCEEDED with the true pose within the tolerances
the file sets; `rosrun dynamic_reconfigure dynparam set
/move_base/TrajectoryPlannerROS max_vel_x 0.1` and the robot's true speed on
the next goal stays below it; a bad value is refused and nothing changes;
/amcl and the costmaps' inflation layers serve their live parameters too.
"""
import math
import os
import textwrap

import pytest
import rospkg
from test_navigation import world_obstacles

from tb3_harness.navigating import BURGER_FOOTPRINT, clearance, closest, running
from tb3_harness.processes import start_master, wait_until
from tb3_harness.report import figure

from tb3_system_utils import run

SPAWN = (-2.0, -0.5, 0.0)  # tb3_world.launch's
GOALS = [(-0.55, -0.55, 0.0), (0.55, 0.55, math.pi / 2)]  # between the pillars, then past the middle one
SLOW_GOAL = (1.65, -0.55, -math.pi / 2)                     # the next one, after max_vel_x 0.1
XY_TOLERANCE, YAW_TOLERANCE = 0.10, 0.15  # the file's TrajectoryPlannerROS/xy_ and yaw_goal_tolerance
CLEARANCE = 0.05          # m: the footprint never nearer to a pillar or wall
SLOW = 0.1                # m/s: dynparam's max_vel_x
SPEED_SLACK = 0.01        # m/s: the simulated motors' overshoot of a command

FILES = {
    'costmap_common_params.yaml': """
        obstacle_range: 2.5
        raytrace_range: 3.0
        robot_radius: 0.15          # the Burger's corners are 0.148 m from base_footprint
        inflation_radius: 0.55
        observation_sources: laser_scan_sensor
        laser_scan_sensor: {sensor_frame: /base_scan, data_type: LaserScan, topic: /scan, marking: true, clearing: true}
        """,
    'global_costmap_params.yaml': """
        global_costmap:
          global_frame: /map
          robot_base_frame: /base_footprint
          update_frequency: 5.0
          static_map: true
        """,
    'local_costmap_params.yaml': """
        local_costmap:
          global_frame: /odom
          robot_base_frame: /base_footprint
          update_frequency: 5.0
          publish_frequency: 2.0
          static_map: false
          rolling_window: true
          width: 6.0
          height: 6.0
          resolution: 0.05
        """,
    'base_local_planner_params.yaml': """
        controller_frequency: 10.0
        TrajectoryPlannerROS:
          max_vel_x: 0.2
          min_vel_x: 0.05
          max_vel_theta: 1.5
          min_vel_theta: -1.5
          min_in_place_vel_theta: 0.6
          escape_vel: -0.1
          acc_lim_theta: 3.2
          acc_lim_x: 2.5
          acc_lim_y: 2.5
          holonomic_robot: false
          xy_goal_tolerance: 0.10
          yaw_goal_tolerance: 0.15
          sim_time: 2.0
          vx_samples: 10
          vtheta_samples: 20
          dwa: true
        """,
}
LAUNCH = """<launch>
  <master auto="start"/>
  <!-- Run the map server -->
  <node name="map_server" pkg="map_server" type="map_server" args="{map}"/>

  <!--- Run AMCL -->
  <node pkg="amcl" type="amcl" name="amcl" output="screen">
    <param name="odom_model_type" value="diff"/>
    <param name="odom_alpha5" value="0.1"/>
    <param name="laser_max_beams" value="60"/>
    <param name="update_min_d" value="0.2"/>
    <param name="odom_frame_id" value="/odom"/>
    <param name="base_frame_id" value="/base_footprint"/>
    <param name="global_frame_id" value="/map"/>
  </node>

  <node pkg="move_base" type="move_base" respawn="false" name="move_base" output="screen">
    <param name="base_local_planner" value="base_local_planner/TrajectoryPlannerROS"/>
    <rosparam file="{dir}/costmap_common_params.yaml" command="load" ns="global_costmap" />
    <rosparam file="{dir}/costmap_common_params.yaml" command="load" ns="local_costmap" />
    <rosparam file="{dir}/local_costmap_params.yaml" command="load" />
    <rosparam file="{dir}/global_costmap_params.yaml" command="load" />
    <rosparam file="{dir}/base_local_planner_params.yaml" command="load" />
  </node>
</launch>
"""


@pytest.fixture(scope='module')
def navigation(tmp_path_factory):
    """The world, the wiki-style launch and this process's Navigation, for every test of the file."""
    import rospy
    folder = str(tmp_path_factory.mktemp('wiki_navigation'))
    for name, text in FILES.items():
        with open(os.path.join(folder, name), 'w') as stream:
            stream.write(textwrap.dedent(text).lstrip())
    launch = os.path.join(folder, 'my_robot_2dnav.launch')
    package = rospkg.RosPack().get_path('tb3_sim_nav')
    with open(launch, 'w') as stream:
        stream.write(LAUNCH.format(map=os.path.join(package, 'maps', 'turtlebot3_world.yaml'), dir=folder))
    master = start_master(folder)
    try:
        os.environ['TURTLEBOT3_MODEL'] = 'burger'
        rospy.init_node('wiki_navigation_test', anonymous=True, disable_signals=True)
        with running(folder, ['tb3_sim_bringup', 'tb3_world.launch', 'real_time_factor:=0'], [launch], SPAWN) as nav:
            yield nav
        rospy.signal_shutdown('wiki navigation tests done')
    finally:
        master.stop()


def true_speed(path, span=0.5):
    """The highest true speed (m/s) along `path` ([t, x, y, yaw] samples), over `span` s of sim time."""
    fastest, first = 0.0, 0
    for last in range(len(path)):
        while path[last][0] - path[first][0] > span:
            first += 1
        if path[last][0] - path[first][0] >= span / 2:
            moved = math.hypot(path[last][1] - path[first][1], path[last][2] - path[first][2])
            fastest = max(fastest, moved / (path[last][0] - path[first][0]))
    return fastest


def dynparam(*arguments):
    return run(['rosrun', 'dynamic_reconfigure', 'dynparam'] + list(arguments), 60.0)


def test_the_parameters_are_read_as_the_originals_read_them(navigation):
    output = navigation.logs[1].output(None)
    assert 'base_local_planner/TrajectoryPlannerROS' in output
    # Taken without effect, and said so: amcl's omni-only noise, TrajectoryPlannerROS's escape.
    assert 'parameter ~odom_alpha5 = 0.1 has no effect here' in output
    assert 'parameter ~TrajectoryPlannerROS/escape_vel = -0.1 has no effect here' in output
    import rospy
    assert rospy.get_param('/move_base/TrajectoryPlannerROS/max_vel_x') == 0.2
    assert rospy.get_param('/move_base/local_costmap/inflation_layer/inflation_radius') == 0.55


def test_two_goals_around_the_pillars_succeed_within_the_files_tolerances(navigation):
    obstacles = world_obstacles()
    for goal in GOALS:
        outcome = navigation.go(*goal)
        least = clearance(outcome.path, obstacles, BURGER_FOOTPRINT)
        print('MEASURED goal (%.2f, %.2f, %.2f): %s in %.1f s of sim time; truly %.3f m and %.3f rad off '
              '(amcl %.3f m off); footprint at least %.3f m from the world; at most %.3f m/s'
              % (goal + (outcome.state, outcome.sim_seconds, outcome.xy_error, outcome.yaw_error,
                         outcome.amcl_error, least, true_speed(outcome.path))))
        figure('wiki_goal_xy_error', outcome.xy_error, 'max', 'm')
        assert outcome.state == 'SUCCEEDED', (goal, outcome.state, outcome.text)
        assert outcome.xy_error <= XY_TOLERANCE and outcome.yaw_error <= YAW_TOLERANCE, outcome
        assert least >= CLEARANCE, (goal, least)


def test_dynparam_slows_the_next_goal_and_a_bad_value_is_refused(navigation):
    import rospy
    changed = dynparam('set', '/move_base/TrajectoryPlannerROS', 'max_vel_x', str(SLOW))
    assert changed.returncode == 0, changed.stdout
    assert rospy.get_param('/move_base/TrajectoryPlannerROS/max_vel_x') == SLOW
    refused = dynparam('set', '/move_base/TrajectoryPlannerROS', 'max_vel_x', '-0.5')
    assert rospy.get_param('/move_base/TrajectoryPlannerROS/max_vel_x') == SLOW, refused.stdout
    wait_until(lambda: 'refused' in navigation.logs[1].output(None), 10.0, 'the refusal in the log')
    assert "parameter ~TrajectoryPlannerROS/max_vel_x = -0.5: must be > 0" in navigation.logs[1].output(None)
    outcome = navigation.go(*SLOW_GOAL)
    fastest = true_speed(outcome.path)
    least, where = closest(outcome.path, world_obstacles(), BURGER_FOOTPRINT)
    print('MEASURED after max_vel_x %.2f: %s in %.1f s of sim time, truly %.3f m off, at most %.3f m/s; footprint '
          'at least %.3f m from the world (at %s)' % (SLOW, outcome.state, outcome.sim_seconds, outcome.xy_error,
                                                    fastest, least, tuple(round(value, 2) for value in where)))
    figure('wiki_slow_speed', fastest, 'max', 'm/s')
    assert outcome.state == 'SUCCEEDED', (outcome.text, outcome.truth, [tuple(round(v, 2) for v in sample)
                                                                        for sample in outcome.path[::20]])
    assert fastest <= SLOW + SPEED_SLACK


def test_amcl_and_the_inflation_layers_serve_their_live_parameters(navigation):
    import rospy
    assert dynparam('set', '/amcl', 'laser_max_beams', '90').returncode == 0
    assert rospy.get_param('/amcl/laser_max_beams') == 90
    dynparam('set', '/amcl', 'laser_model_type', 'beam')
    assert rospy.get_param('/amcl/laser_model_type') == 'likelihood_field'
    assert dynparam('set', '/move_base/global_costmap/inflation_layer', 'inflation_radius', '0.4').returncode == 0
    assert rospy.get_param('/move_base/global_costmap/inflation_layer/inflation_radius') == 0.4
    output = ''.join(process.output(None) for process in navigation.logs)
    assert "refused" in output and "~laser_model_type = 'beam'" in output
