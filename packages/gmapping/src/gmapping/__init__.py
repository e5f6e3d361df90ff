"""The ROS node(s) of the package gmapping, over tb3_navigation's cores."""
