"""A pybullet TurtleBot3 Burger that stands in for Gazebo on Debian's ROS 1.

Everything here is plain Python, numpy and pybullet, without ROS; the ROS
edge is the subpackage `ros` (doc/design.md has the picture).
"""
