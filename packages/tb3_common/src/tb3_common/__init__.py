"""The shared pieces of the simulator and the navigation nodes: poses, grids, map files (no ROS)."""
