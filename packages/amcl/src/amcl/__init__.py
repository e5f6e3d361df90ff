"""The ROS node(s) of the package amcl, over tb3_navigation's cores."""
