# make test (run with bash, inside `source setup.bash`): the unit tests
# (pytest, no master), catkin_lint, the system tests, then the integration
# tests with catkin_make run_tests (rostest starts a master of its own on a free
# port for each). Exit status: 0 only if all pass.
# Each part's output is shown as it runs and kept; the lines that say why a
# part failed are repeated at the end, where a CI log's tail shows them.
set -uo pipefail
cd "$(dirname "$0")/.."
export ROS_HOSTNAME=localhost
unset ROS_IP
logs=$(mktemp -d)
trap 'rm -rf "$logs"' EXIT
failures=()

# run NAME COMMAND...: run it, its output to the terminal and to $logs/NAME.
# What it starts carries TB3_RUN=NAME.PID; any such process still running
# after it fails the part (tb3_harness.leftovers names and ends it).
run() {
  local name=$1
  shift
  TB3_RUN="$name.$$" "$@" 2>&1 | tee "$logs/$name" || failures+=("$name")
  TB3_RUN="$name.$$" python3 -m tb3_harness.leftovers check "$name" 2>&1 | tee -a "$logs/$name" \
    || failures+=("$name (left processes running)")
}

# The lines of a failed part's output that say what failed: rostest's failure
# headers with the message after each, pytest's short summary, the exception
# line of each traceback, the soak's missed rows.
why() {
  { grep -E -A1 '\]\[(FAILURE|ERROR)\]' "$1"
    grep -E '^(FAILED|ERROR) |(Error|Exception)(: |$)|  MISSED$|FAILED: |^Summary: |LEFT RUNNING' "$1"
  } | grep -v '^--$' | awk '!seen[$0]++' | head -40
}

if [ "${1:-}" != --integration-only ]; then
  echo "== unit tests (pytest, no master)"
  run unit python3 -m pytest -q -p no:cacheprovider test/unit
  echo "== catkin_lint"
  lint=$(catkin_lint --strict -W2 $(for package in tb3_sim_nav gazebo_msgs map_server tb3_navigation; do
    echo "$(rospack find $package)"; done) 2>&1)
  echo "$lint" | tee "$logs/catkin_lint"
  echo "$lint" | grep -qE ': (error|warning|notice):' && failures+=(catkin_lint)
fi

# What rostest cannot stage (its master is its own): a master killed and
# restarted, bad start-up configurations, and the tutorial's scripts run at
# factors 1, 5 and 0 against one another (a fresh simulator for each run).
# One pytest process per file: a process can be one rospy node only, and each
# file that is one talks to a master of its own.
for test_file in test/system/test_*.py; do
  name=$(basename "$test_file" .py)
  echo "== system tests: $name (pytest, masters of their own)"
  run "$name" python3 -m pytest -q -p no:cacheprovider "$test_file"
done

# The rostests (test/*.test) the ROS way, as the README shows, in make setup's
# workspace: one at a time (CMakeLists.txt), each with a master of its own.
# catkin_make run_tests exits 0 whatever the tests say; catkin_test_results
# tells. SIGINT first on a time-out: rostest then stops every node it started.
echo "== rostests: catkin_make run_tests in .ws"
run rostests bash -c 'cd .ws && timeout --signal=INT --kill-after=60 3600 catkin_make run_tests &&
  catkin_test_results build/test_results'

if [ "${1:-}" != --integration-only ]; then
  echo "== short soak: 120 s of sim time under random and hostile commands"
  run soak timeout --signal=INT --kill-after=20 600 python3 tools/soak.py --sim-seconds 120 --check
fi

if [ ${#failures[@]} -gt 0 ]; then
  for name in "${failures[@]}"; do
    echo "== why $name failed"
    why "$logs/$name"
  done
  echo "FAILED: ${failures[*]}"
  exit 1
fi
echo "ALL PASSED"
