"""A move_base that aborts every goal at once: the explore node's bad case (issue 21).

    python3 aborting_move_base.py      (a node named move_base, serving the move_base action)

It prints one line per goal it aborts, so the test can count them.
"""
import actionlib
from move_base_msgs.msg import MoveBaseAction, MoveBaseResult

from tb3_common.ros import lifecycle


def main():
    life = lifecycle.init_node('move_base')
    aborted = []

    def abort(goal):
        aborted.append(goal)
        position = goal.target_pose.pose.position
        print('aborted goal %d (%.2f, %.2f)' % (len(aborted), position.x, position.y), flush=True)
        server.set_aborted(MoveBaseResult(), 'Failed to find a valid plan. Even after executing recovery behaviors.')
    server = actionlib.SimpleActionServer('move_base', MoveBaseAction, execute_cb=abort, auto_start=False)
    server.start()
    life.spin()


if __name__ == '__main__':
    main()
