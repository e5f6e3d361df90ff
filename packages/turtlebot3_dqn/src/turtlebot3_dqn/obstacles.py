"""Stage 3's and stage 4's moving obstacles (ROBOTIS' moving_obstacle, combination_obstacle_1/2).

Every 0.1 s each node reads the model's pose from gazebo/model_states and
publishes a ModelState on gazebo/set_model_state: moving_obstacle the pose
with a twist of 0.5 rad/s about z (Gazebo's physics turns the model);
combination_obstacle_N the pose moved by its leg's step, legs changing when
the model comes within 0.05 m (in x and in y) of the leg's end, and back to
the first leg at the start. ROBOTIS' nodes wait 0.1 s of wall time; these
wait 0.1 s of sim time, so the obstacles move the same at any factor.
`Combination` is the pure part; `run` the thin ROS edge.
"""
PERIOD = 0.1        # s between two ModelStates
TURN = 0.5          # rad/s: moving_obstacle's twist of the model `obstacle`
NEAR = 0.05         # m: a leg ends within this of its end point (in x and in y)

#: Each leg: (dx, dy) per PERIOD, and the point that ends it. combination_obstacle_1's obstacle_1 starts
#: at (2, 2); combination_obstacle_2's obstacle_2 at (-2, -2).
LEGS = {
    'obstacle_1': ((2.0, 2.0), [
        ((-0.005, -0.012), (1.5, 0.8)), ((-0.01, 0.007), (0.5, 1.5)), ((-0.008, -0.002), (-0.3, 1.3)),
        ((-0.007, -0.005), (-1.0, 0.8)), ((-0.01, 0.007), (-2.0, 1.5)), ((-0.002, -0.007), (-2.2, 0.8)),
        ((0.004, -0.011), (-1.8, -0.3)), ((0.003, -0.007), (-1.5, -1.0)), ((0.009, 0.007), (-0.6, -0.3)),
        ((0.011, -0.011), (0.5, -1.4)), ((0.006, -0.006), (1.1, -2.0)), ((0.009, 0.01), (2.0, -1.0)),
        ((-0.008, 0.01), (1.2, 0.0)), ((-0.007, 0.005), (0.5, 0.5)), ((0.017, 0.008), (2.2, 1.3)),
        ((-0.002, 0.007), (2.0, 2.0))]),
    'obstacle_2': ((-2.0, -2.0), [
        ((0.007, -0.001), (-1.3, -2.1)), ((0.009, 0.009), (-0.4, -1.2)), ((-0.006, 0.006), (-1.0, -0.6)),
        ((0.008, -0.001), (-0.2, -0.7)), ((0.013, -0.013), (1.1, -2.0)), ((0.009, 0.01), (2.0, -1.0)),
        ((-0.008, 0.01), (1.2, 0.0)), ((-0.007, 0.02), (0.5, 2.0)), ((-0.013, -0.001), (-2.1, 1.8)),
        ((0.008, -0.008), (-0.5, 0.2)), ((-0.002, -0.0115), (-0.9, -2.1)), ((-0.011, 0.001), (-2.0, -2.0))]),
}
NODES = {'combination_obstacle_1': 'obstacle_1', 'combination_obstacle_2': 'obstacle_2'}


def _near(x, y, point):
    return abs(x - point[0]) < NEAR and abs(y - point[1]) < NEAR


class Combination(object):
    """combination_obstacle_N's state machine for one model: next(x, y) -> the (x, y) to set."""

    def __init__(self, model):
        self.start, self.legs = LEGS[model]
        self.leg = 0

    def next(self, x, y):
        if _near(x, y, self.start):
            self.leg = 0
        (dx, dy), end = self.legs[self.leg]
        x, y = x + dx, y + dy
        if _near(x, y, end):
            self.leg = (self.leg + 1) % len(self.legs)
        return x, y


def run(node):
    """The node `node` (moving_obstacle, combination_obstacle_1 or _2) until Ctrl+C."""
    import rospy
    from gazebo_msgs.msg import ModelState, ModelStates

    from tb3_common.ros import lifecycle

    life = lifecycle.init_node(node)
    model = NODES.get(node, 'obstacle')
    mover = Combination(model) if node in NODES else None
    latest = {}
    rospy.Subscriber('gazebo/model_states', ModelStates, life.callback(
        lambda states: latest.update((name, pose) for name, pose in zip(states.name, states.pose) if name == model)),
        queue_size=1)
    publisher = rospy.Publisher('gazebo/set_model_state', ModelState, queue_size=1)
    while not life.stopping:
        if not life.sleep_sim(PERIOD):
            break
        if model not in latest:
            continue
        state = ModelState(model_name=model, pose=latest[model], reference_frame='world')
        if mover is None:
            state.twist.angular.z = TURN
        else:
            state.pose.position.x, state.pose.position.y = mover.next(state.pose.position.x, state.pose.position.y)
        publisher.publish(state)
    life.finish()
