"""turtlebot3_teleop's node turtlebot3_teleop_key: the speeds keys give (keys) and the terminal and ROS (teleop_key)."""
