"""turtlebot3_gazebo's node turtlebot3_drive: the wandering's core (drive) and its ROS edge (drive_node)."""
