"""The simulator's ROS edge: node wiring, message filling, lockstep, the
master watch, a transport that never blocks the step loop, and the one
module (rospy_internals) for every use of rospy's internals."""
