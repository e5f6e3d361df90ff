"""The ROS node(s) of the package move_base, over tb3_navigation's cores."""
