"""A pybullet TurtleBot3 Burger that stands in for Gazebo on Debian's ROS 1.

Everything here is plain Python and numpy except `ros_node`, the one module
that imports rospy.
"""
