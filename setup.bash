# Source me (`source setup.bash`) for a shell where the tutorial's commands
# work: the catkin workspace that `make setup` built, the project's venv
# (Debian's /usr/bin/python3 plus pybullet) first on PATH whatever python
# came first before, and ROS bound to this machine's loopback unless you
# chose an address yourself (ROS_IP or ROS_HOSTNAME, for a second machine).
_tb3_root="$(cd "$(dirname "${BASH_SOURCE[0]:-$0}")" && pwd)"
if [ -f "$_tb3_root/.ws/devel/setup.bash" ]; then
  source "$_tb3_root/.ws/devel/setup.bash"
  # The venv first, also when it is on PATH already behind another python.
  _tb3_path=":$PATH:"
  _tb3_path="${_tb3_path//:$_tb3_root\/.venv\/bin:/:}"
  _tb3_path="${_tb3_path#:}"
  export PATH="$_tb3_root/.venv/bin:${_tb3_path%:}"
  unset _tb3_path
  # ROS_HOSTNAME wins over ROS_IP: set it only if neither is set.
  [ -n "${ROS_HOSTNAME:-}${ROS_IP:-}" ] || export ROS_HOSTNAME=localhost
  export ROS_MASTER_URI="${ROS_MASTER_URI:-http://localhost:11311}"
else
  echo "tb3_sim_nav: run 'make setup' in $_tb3_root first" >&2
fi
unset _tb3_root
