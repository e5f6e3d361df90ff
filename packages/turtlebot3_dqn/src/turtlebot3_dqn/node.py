"""The node turtlebot3_dqn_stage_N: the thin ROS edge of ROBOTIS' agent (training.py, environment.py).

Publishes `result` (Float32MultiArray [score, average max Q]) at each
episode's end and `get_action` ([action, score, reward]) at each step, as
ROBOTIS'; its parameters are config.py's (private, ROBOTIS' names and
values as defaults). Ends within 2 s of Ctrl+C (tb3_common's lifecycle).
"""
import os

import rospkg
import rospy
from std_msgs.msg import Float32MultiArray

from tb3_common.ros import lifecycle
from tb3_common.ros.params import read_or_exit

from .config import AgentConfig, NodeConfig
from .ending import finish_now
from .environment import Env, SimulatorMissing
from .graphs import write_png
from .training import Trainer, read_results


def main(stage):
    name = 'turtlebot3_dqn_stage_%d' % stage
    life = lifecycle.init_node(name)
    config = read_or_exit(name, NodeConfig)
    agent_config = read_or_exit(name, AgentConfig)
    launched = rospy.get_param('/stage_number', stage)  # ROBOTIS' launch sets it; respawnGoal reads it
    if int(launched) != stage:
        rospy.logwarn('%s: /stage_number is %s: this node plays stage %d', name, launched, stage)
    # ROBOTIS' saves in the package's save_model/, which an installed package cannot write: ROS_HOME here.
    save_dir = config.save_dir or os.path.join(rospkg.get_ros_home(), 'turtlebot3_dqn')
    results = rospy.Publisher('result', Float32MultiArray, queue_size=5)
    actions = rospy.Publisher('get_action', Float32MultiArray, queue_size=5)
    status = 0
    try:
        env = Env(stage, seed=config.seed, episode_step=config.episode_step, scan_timeout=config.scan_timeout,
                  life=life)
        trainer = Trainer(env, config, agent_config, stage, save_dir, log=rospy.loginfo)
        for episode in trainer.episodes(on_step=lambda action, score, reward: actions.publish(
                Float32MultiArray(data=[action, score, reward]))):
            results.publish(Float32MultiArray(data=[episode.score, episode.max_q]))
            if config.result_png and episode.episode % config.save_every == 0:
                write_png(read_results(trainer.results), config.result_png, 'stage %d' % stage)
            if life.stopping:
                break
    except KeyboardInterrupt:  # an end asked for while it waited (environment.py)
        pass
    except (SimulatorMissing, ValueError, OSError) as error:
        if not life.stopping:
            rospy.logfatal('%s: %s', name, error)
            life.request_stop(str(error))
            status = 1
    finish_now(life, status)
