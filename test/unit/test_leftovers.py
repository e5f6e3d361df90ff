"""tb3_harness.leftovers: what a run started and left running is found, named and ended."""
import subprocess
import sys

from tb3_harness import leftovers


def test_a_process_left_running_is_found_and_ended_one_that_ended_is_not():
    with leftovers.Guard('a test run', grace=0.5) as guard:
        done = subprocess.Popen(['true'])
        left = subprocess.Popen(['sleep', '60'], start_new_session=True)  # a group of its own, as nodes have
        done.wait()
    assert [pid for pid, _ in guard.left] == [left.pid]
    assert 'sleep 60' in guard.left[0][1]
    assert left.wait(5) == -9  # ended by the check


def test_the_checker_and_its_ancestors_are_not_counted():
    with leftovers.Guard('nothing started') as guard:
        status = subprocess.call([sys.executable, '-m', 'tb3_harness.leftovers', 'check', 'a child checker'])
    assert status == 0 and guard.left == []


def test_run_fails_a_tool_that_left_a_process():
    children = []

    def tool():
        children.append(subprocess.Popen(['sleep', '60']))
        return 0
    assert leftovers.run('a tool', tool, grace=0.5) == 1
    assert children[0].wait(5) == -9
