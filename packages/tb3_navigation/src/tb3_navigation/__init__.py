"""Mapping and navigation algorithms (numpy, scipy; no ROS); their nodes are the packages amcl, move_base,
gmapping, explore_lite and multirobot_map_merge."""
