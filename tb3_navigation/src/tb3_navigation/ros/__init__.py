"""The ROS edges of the navigation cores: one node a module, rospy only here."""
