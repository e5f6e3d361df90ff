"""turtlebot3_fake's node turtlebot3_fake_node: the fake robot's core (fake) and its ROS edge (fake_node)."""
