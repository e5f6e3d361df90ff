"""quiescence.py on real processes and threads, and on a /proc written by hand
for the cases a real process cannot be made to show on cue."""
import socket
import subprocess
import sys
import threading
import time

import pytest

from tb3_sim_nav import quiescence
from tb3_sim_nav.quiescence import InputWaits, ProcessGone, ProcessWatch

SETTLE = 5.0  # wall s a real process or thread gets to reach the state a test waits for


def eventually(condition, timeout=SETTLE):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if condition():
            return True
        time.sleep(0.01)
    return False


@pytest.fixture
def child():
    """Start a python child running `code`; killed afterwards whatever happens."""
    children = []

    def start(code):
        process = subprocess.Popen([sys.executable, '-c', code])
        children.append(process)
        return process
    yield start
    for process in children:
        process.kill()
        process.wait()


def test_a_sleeping_process_is_waiting(child):
    process = child('import threading, time\n'
                    'threading.Thread(target=time.sleep, args=(60,), daemon=True).start()\n'
                    'time.sleep(60)')
    watch = ProcessWatch(process.pid)
    assert eventually(watch.waiting)
    assert len(watch.snapshot()) >= 2  # both threads looked at
    watch.close()


def test_a_computing_process_is_not_waiting(child):
    process = child('while True: pass')
    watch = ProcessWatch(process.pid)
    time.sleep(0.2)
    assert not any(watch.waiting() for _ in range(20))
    watch.close()


def test_a_process_whose_thread_computes_is_not_waiting(child):
    process = child('import threading, time\n'
                    'def spin():\n'
                    '    while True: pass\n'
                    'threading.Thread(target=spin, daemon=True).start()\n'
                    'time.sleep(60)')
    watch = ProcessWatch(process.pid)
    time.sleep(0.2)
    assert not any(watch.waiting() for _ in range(20))
    watch.close()


def test_a_thread_that_ran_between_the_two_looks_is_not_waiting(tmp_path):
    """Asleep at both looks, but its run counters moved: it ran in between."""
    task = tmp_path / '42' / 'task'
    write_thread(task, 42, b'42 (python3) S 1 42', schedstat=b'1000 0 3\n')
    watch = ProcessWatch(42, proc=str(tmp_path))
    assert watch.waiting()
    first_look = watch._look

    def look_then_run(threads, states):
        counters = first_look(threads, states)
        write_thread(task, 42, b'42 (python3) S 1 42', schedstat=b'1900 0 4\n')
        return counters
    watch._look = look_then_run
    assert not watch.waiting()
    watch.close()


def test_the_thread_last_seen_busy_is_asked_first(tmp_path):
    task = tmp_path / '5' / 'task'
    for tid in (5, 6, 7):
        write_thread(task, tid, b'%d (n) S 1 5 5' % tid)
    write_thread(task, 7, b'7 (n) R 1 5 5')
    watch = ProcessWatch(5, proc=str(tmp_path))
    assert not watch.waiting()
    looks = []
    watch._look = lambda threads, states: looks.append(states)
    assert not watch.waiting()
    assert looks == [], 'still busy: no need to look at every thread'
    watch.close()


def write_thread(task_dir, tid, stat, schedstat=b'5 0 1\n'):
    thread = task_dir / str(tid)
    thread.mkdir(parents=True, exist_ok=True)
    (thread / 'stat').write_bytes(stat)
    if schedstat is not None:
        (thread / 'schedstat').write_bytes(schedstat)


def test_the_state_is_read_after_a_command_name_with_spaces_and_parentheses(tmp_path):
    task = tmp_path / '7' / 'task'
    write_thread(task, 7, b'7 (odd) name) R 1 7 7')
    write_thread(task, 8, b'8 (x) S 1 7 7')
    assert ProcessWatch(7, proc=str(tmp_path)).snapshot() is None
    write_thread(task, 7, b'7 (odd) name) S 1 7 7')
    assert ProcessWatch(7, proc=str(tmp_path)).waiting()


@pytest.mark.parametrize('state,waiting', [(b'S', True), (b'T', True), (b'Z', True),
                                           (b'R', False), (b'D', False)])
def test_stopped_and_dead_threads_wait_but_runnable_and_disk_ones_do_not(tmp_path, state, waiting):
    write_thread(tmp_path / '9' / 'task', 9, b'9 (n) ' + state + b' 1 9 9')
    assert ProcessWatch(9, proc=str(tmp_path)).waiting() is waiting


def test_without_scheduler_statistics_the_states_alone_decide(tmp_path):
    write_thread(tmp_path / '9' / 'task', 9, b'9 (n) S 1 9 9', schedstat=None)
    assert ProcessWatch(9, proc=str(tmp_path)).waiting()


def test_threads_that_come_and_go_are_followed(tmp_path):
    task = tmp_path / '9' / 'task'
    write_thread(task, 9, b'9 (n) S 1 9 9')
    watch = ProcessWatch(9, proc=str(tmp_path))
    assert watch.waiting()
    write_thread(task, 10, b'10 (n) R 1 9 9')
    assert not watch.waiting()
    for name in ('stat', 'schedstat'):
        (task / '10' / name).unlink()
    (task / '10').rmdir()
    assert watch.waiting()
    watch.close()


def test_a_missing_or_ended_process_is_gone(child, tmp_path):
    with pytest.raises(ProcessGone):
        ProcessWatch(12345, proc=str(tmp_path))
    process = child('import time; time.sleep(60)')
    watch = ProcessWatch(process.pid)
    process.kill()
    process.wait()
    with pytest.raises(ProcessGone):
        watch.waiting()
    watch.close()


@pytest.mark.skipif(quiescence.IO_WAIT_SYSCALLS is None, reason='syscall numbers unknown on this machine')
def test_a_thread_waits_for_input_only_while_blocked_reading_its_socket():
    """As rospy's receive threads: a socket with a timeout, recv in a loop."""
    ours, theirs = socket.socketpair()
    ours.settimeout(60.0)
    lock = threading.Lock()
    receivers = InputWaits()
    handled = []

    def receive():
        receivers.add(threading.get_native_id())
        while True:
            data = ours.recv(64)
            if not data:
                return
            with lock:  # held by the test: a callback waiting for a lock
                handled.append(data)
    thread = threading.Thread(target=receive, daemon=True)
    thread.start()
    try:
        assert eventually(receivers.all_waiting)
        with lock:
            theirs.sendall(b'twist')
            assert eventually(lambda: not receivers.all_waiting())
            time.sleep(0.1)
            assert not receivers.all_waiting(), 'blocked on a lock is not waiting for input'
        assert eventually(lambda: handled and receivers.all_waiting())
    finally:
        theirs.close()
        thread.join(SETTLE)
        ours.close()
    # join() returns a moment before the kernel has ended the thread.
    assert eventually(receivers.all_waiting), 'an ended thread has nothing left to handle'
    receivers.clear()
    assert receivers.all_waiting(), 'no thread followed: nothing to wait for'


def test_own_threads_are_quiet_after_a_pause_and_then_until_one_runs(tmp_path):
    """quiet(): two looks a pause apart the first time; afterwards one look, unless a thread ran since."""
    task = tmp_path / '8' / 'task'
    write_thread(task, 8, b'8 (step loop) R 1 8', schedstat=b'1 0 1\n')
    write_thread(task, 9, b'9 (service) S 1 8', schedstat=b'1000 0 3\n')
    watch = ProcessWatch(8, proc=str(tmp_path), exclude=(8,))
    pauses = []
    assert watch.quiet(0.001, sleep=pauses.append) and pauses == [0.001]
    assert watch.quiet(0.001, sleep=pauses.append) and pauses == [0.001], 'nothing ran: no second look'
    write_thread(task, 9, b'9 (service) S 1 8', schedstat=b'1500 0 4\n')  # it ran (a request came)
    assert watch.quiet(0.001, sleep=pauses.append) and len(pauses) == 2
    write_thread(task, 9, b'9 (service) R 1 8', schedstat=b'1500 0 4\n')  # woken, not yet run
    assert not watch.quiet(0.001, sleep=pauses.append)

    def runs_in_the_pause(_pause):
        write_thread(task, 9, b'9 (service) S 1 8', schedstat=b'1900 0 5\n')
    write_thread(task, 9, b'9 (service) S 1 8', schedstat=b'1600 0 5\n')
    assert not watch.quiet(0.001, sleep=runs_in_the_pause)
    watch.close()
