"""The ROS node(s) of the package explore_lite, over tb3_navigation's cores."""
