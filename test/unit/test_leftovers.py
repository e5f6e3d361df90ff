"""tb3_harness.leftovers: what a run started and left running is found, named and ended."""
import subprocess
import sys
import time

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


def test_a_process_caught_in_the_middle_of_exec_is_read_again(monkeypatch):
    # Just after fork returns, the child may be between exec's new memory and its
    # arguments: no environment, no command line (2% of spawns on 2 busy cores).
    proc = {'environ': b'', 'cmdline': b'', 'stat': b'7 (sleep) R 1 7 7 0 -1 4194560 0'}
    real_sleep = leftovers.time.sleep

    def exec_ends(seconds):
        proc.update(environ=b'A=1\0%s=run\0' % leftovers.TAG.encode(), cmdline=b'sleep\x0060\0')
        real_sleep(seconds)
    monkeypatch.setattr(leftovers, '_read', lambda pid, name: proc[name])
    monkeypatch.setattr(leftovers.time, 'sleep', exec_ends)
    assert b'%s=run' % leftovers.TAG.encode() in leftovers._environ(7)


def test_kernel_threads_and_zombies_are_not_waited_for(monkeypatch):
    stats = {1: b'2 (kthreadd) S 0 0 0 0 -1 2129984 0', 2: b'9 (sleep) Z 1 9 9 0 -1 4194564 0'}
    monkeypatch.setattr(leftovers, '_read', lambda pid, name: stats[pid] if name == 'stat' else b'')
    started = time.monotonic()
    assert leftovers._environ(1) == [b''] and leftovers._environ(2) == [b'']
    assert time.monotonic() - started < 0.5 * leftovers.SETTLE
