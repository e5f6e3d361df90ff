"""Mapping and navigation cores (numpy, scipy; no ROS) and their ROS edges (tb3_navigation.ros)."""
