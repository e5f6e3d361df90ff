# make test (run with bash, inside `source setup.bash`): the unit tests
# (pytest, no master), catkin_lint, then each integration test with rostest,
# which starts its own master on a free port. Exit status: 0 only if all pass.
set -uo pipefail
cd "$(dirname "$0")/.."
export ROS_HOSTNAME=localhost
unset ROS_IP
failures=()

if [ "${1:-}" != --integration-only ]; then
  echo "== unit tests (pytest, no master)"
  python3 -m pytest -q -p no:cacheprovider test/unit || failures+=(unit)
  echo "== catkin_lint"
  lint=$(catkin_lint --strict -W2 "$(rospack find tb3_sim_nav)" 2>&1)
  echo "$lint"
  echo "$lint" | grep -qE ': (error|warning|notice):' && failures+=(catkin_lint)
fi

# What rostest cannot stage (its master is its own): a master killed and
# restarted, bad start-up configurations, and the tutorial's scripts run at
# factors 1, 5 and 0 against one another (a fresh simulator for each run).
echo "== system tests (pytest, masters of their own)"
python3 -m pytest -q -p no:cacheprovider test/system || failures+=(system)

for test_file in test/*.test; do
  name=$(basename "$test_file")
  echo "== rostest tb3_sim_nav $name"
  # Not --text: with it rostest exits 0 even when a test fails. SIGINT first on
  # a time-out: rostest then stops every node it started.
  timeout --signal=INT --kill-after=20 600 rostest tb3_sim_nav "$name" || failures+=("$name")
done

if [ "${1:-}" != --integration-only ]; then
  echo "== short soak: 120 s of sim time under random and hostile commands"
  timeout --signal=INT --kill-after=20 600 python3 tools/soak.py --sim-seconds 120 --check || failures+=(soak)
fi

if [ ${#failures[@]} -gt 0 ]; then
  echo "FAILED: ${failures[*]}"
  exit 1
fi
echo "ALL PASSED"
