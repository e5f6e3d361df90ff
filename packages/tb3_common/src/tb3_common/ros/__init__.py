"""What every node of ours shares at its ROS edge: the lifecycle, the parameter layer, tf frames, map messages."""
