"""Stand-in for the *ROS by Example* rbx1_nav package, so its scripts run unchanged."""
