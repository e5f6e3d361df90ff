"""The ROS node(s) of the package map_server, over tb3_navigation's cores."""
