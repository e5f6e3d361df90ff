"""tb3_harness.parts: make test's parts run side by side within their slots, in the plan's order,
each failing on its exit status or on what it left running, with the lines that say why."""
import os
import signal
import subprocess
import sys
import time

import pytest

from tb3_harness.parts import Part, PlanError, Schedule, read_plan, why


def test_a_plan_is_read_in_order_and_its_commands_kept_whole():
    plan = read_plan("# a comment\n\n3 ctrl_c python3 -m pytest -k 'not slow' x.py\n1 lint  catkin_lint --strict\n")
    assert plan == [Part(3, 'ctrl_c', "python3 -m pytest -k 'not slow' x.py"), Part(1, 'lint', 'catkin_lint --strict')]


@pytest.mark.parametrize('line', ['one unit pytest', '0 unit pytest', '2 unit', '1 unit a\n1 unit b'])
def test_a_bad_plan_line_is_refused_naming_it(line):
    with pytest.raises(PlanError, match='plan line'):
        read_plan(line)


def _order(plan, slots, durations):
    """Simulated run: (name, start, end) of each part, whole seconds, as the Schedule starts them."""
    schedule, now, ends, timeline = Schedule(plan, slots), 0, {}, []
    while not schedule.done():
        part = schedule.next()
        while part is not None:
            ends[part.name] = now + durations[part.name]
            timeline.append((part.name, now, ends[part.name]))
            part = schedule.next()
        now = min(ends[part.name] for part in schedule.running)
        for part in [part for part in schedule.running if ends[part.name] == now]:
            schedule.ended(part)
    return timeline


def test_parts_fill_the_slots_in_plan_order_and_an_alone_part_waits_for_an_empty_machine():
    plan = [Part(3, 'ctrl_c', ''), Part(1, 'rostests', ''), Part(2, 'unit', ''), Part(2, 'soak', ''),
            Part(1, 'readme', ''), Part(1, 'models', '')]
    durations = {'ctrl_c': 2, 'rostests': 10, 'unit': 4, 'soak': 3, 'readme': 5, 'models': 1}
    assert _order(plan, 3, durations) == [
        ('ctrl_c', 0, 2),                      # alone: nothing beside it
        ('rostests', 2, 12), ('unit', 2, 6),   # 1 + 2 slots: full
        ('soak', 6, 9),                        # the busy ones one after another, beside the rostests
        ('readme', 9, 14), ('models', 9, 10)]
    # One slot: one part at a time, in the plan's order.
    assert [start for _, start, _ in _order(plan, 1, durations)] == [0, 2, 12, 16, 19, 24]


def test_a_part_waiting_for_slots_lets_smaller_ones_pass_and_starts_when_enough_are_free():
    plan = [Part(1, 'a', ''), Part(1, 'b', ''), Part(2, 'busy', ''), Part(1, 'c', ''), Part(3, 'alone', ''),
            Part(1, 'd', '')]
    durations = {'a': 2, 'b': 5, 'busy': 4, 'c': 6, 'alone': 1, 'd': 1}
    assert _order(plan, 3, durations) == [
        ('a', 0, 2), ('b', 0, 5), ('c', 0, 6),   # busy does not fit beside a and b: c passes it
        ('d', 2, 3),                             # one slot free: d passes busy and alone
        ('busy', 5, 9),                          # two free at once
        ('alone', 9, 10)]                        # alone at the end: everything else has passed it


def test_once_only_parts_of_one_slot_are_left_one_more_runs_beside_them():
    plan = [Part(1, 'rostests', ''), Part(2, 'busy', ''), Part(1, 'a', ''), Part(1, 'b', ''), Part(1, 'c', ''),
            Part(1, 'd', ''), Part(1, 'e', '')]
    durations = {'rostests': 10, 'busy': 4, 'a': 5, 'b': 5, 'c': 5, 'd': 5, 'e': 5}
    assert _order(plan, 3, durations) == [
        ('rostests', 0, 10), ('busy', 0, 4),     # 1 + 2 slots: full, and a part of 2 slots runs
        ('a', 4, 9), ('b', 4, 9), ('c', 4, 9),   # busy has ended: four waiting parts side by side
        ('d', 9, 14), ('e', 9, 14)]
    # Not while a part of 2 slots still waits: it would wait behind every waiting part.
    waits = [Part(1, 'a', ''), Part(1, 'b', ''), Part(1, 'c', ''), Part(2, 'busy', ''), Part(1, 'd', '')]
    assert _order(waits, 3, dict(a=2, b=2, c=2, busy=1, d=1))[:4] == [
        ('a', 0, 2), ('b', 0, 2), ('c', 0, 2), ('busy', 2, 3)]
    # With one slot, still one part at a time.
    assert [start for _, start, _ in _order(plan, 1, durations)] == [0, 10, 14, 19, 24, 29, 34]


def test_why_keeps_the_lines_that_say_what_failed_once_each():
    output = '\n'.join([
        'collected 3 items', '....F', 'E       AssertionError: the robot moved 0.3 m',
        '[tb3_sim_nav.rosunit-x/test_y][FAILURE]', 'ended 0.2 m from its start', 'more noise',
        'FAILED test/system/test_a.py::test_b - AssertionError: the robot moved 0.3 m',
        'E       AssertionError: the robot moved 0.3 m', 'Summary: 10 tests, 0 errors, 1 failures, 0 skipped',
        'tf rate                30 Hz  MISSED', 'all good'])
    assert why(output) == [
        '[tb3_sim_nav.rosunit-x/test_y][FAILURE]', 'ended 0.2 m from its start',
        'E       AssertionError: the robot moved 0.3 m',
        'FAILED test/system/test_a.py::test_b - AssertionError: the robot moved 0.3 m',
        'Summary: 10 tests, 0 errors, 1 failures, 0 skipped', 'tf rate                30 Hz  MISSED']


def test_a_real_run_side_by_side_fails_on_status_and_leftovers_and_says_why(tmp_path):
    """Four parts in three slots: three start at once, the fourth as one ends; a part that exits 1
    and one that leaves a sleeper behind fail, named at the end with their lines; each part's CPU
    time is its whole process tree's."""
    plan = tmp_path / 'plan'
    plan.write_text('1 ok sleep 1; echo fine\n'
                    '1 bad sleep 1; echo "E       AssertionError: broken on purpose"; exit 1\n'
                    '1 leaver sleep 1; (setsid sleep 60 &)\n'
                    '1 spin python3 -c "import time; end = time.process_time() + 1.5; '
                    'exec(\'while time.process_time() < end: pass\')"\n')
    done = subprocess.run([sys.executable, '-m', 'tb3_harness.parts', str(plan), str(tmp_path / 'logs')],
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True, timeout=60)
    print(done.stdout)
    assert done.returncode == 1
    assert '== leaver: started at 0:00 (1 slot, beside ok, bad)' in done.stdout   # side by side, not in turn
    # Once a slot is free, before the 5 s the leftovers check gives the leaver's sleeper.
    assert done.stdout.index('== spin: started') < done.stdout.index('== leaver: FAILED')
    assert '== ok: passed' in done.stdout and 'fine' in done.stdout
    assert '== bad: FAILED (exit status 1)' in done.stdout
    assert '== leaver: FAILED (left 1 process(es) running)' in done.stdout
    assert 'LEFT RUNNING after leaver' in done.stdout and 'sleep 60' in done.stdout
    # The CPU column: a second and a half of python's own, a sleeper's next to none.
    rows = dict((line.split()[0], line.split()[1:]) for line in done.stdout.splitlines()
                if line.split()[:1] in (['spin'], ['ok']) and len(line.split()) == 6)
    assert rows['spin'][3] == '0:02' and rows['ok'][3] == '0:00', rows
    tail = done.stdout[done.stdout.index('== why bad failed'):]
    assert 'E       AssertionError: broken on purpose' in tail
    assert tail.rstrip().endswith('FAILED: bad leaver') or tail.rstrip().endswith('FAILED: leaver bad')


def test_a_second_sigterm_while_the_parts_stop_leaves_none_running(tmp_path):
    """CI stops make test with SIGTERM and may send it again: the parts still running are stopped
    all the same, each as Ctrl+C would (each here takes a second to end on SIGINT)."""
    slow = tmp_path / 'slow.py'
    slow.write_text('import os, sys, time\nopen(sys.argv[1], "w").write(str(os.getpid()))\n'
                    'try:\n    time.sleep(60)\nexcept KeyboardInterrupt:\n    time.sleep(1)\n')
    plan = tmp_path / 'plan'
    plan.write_text(''.join('1 slow%d python3 %s %s\n' % (index, slow, tmp_path / ('pid%d' % index))
                            for index in range(2)))
    runner = subprocess.Popen([sys.executable, '-m', 'tb3_harness.parts', str(plan), str(tmp_path / 'logs')],
                              stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True)
    pids = []
    try:
        deadline = time.monotonic() + 20
        while len(pids) < 2 and time.monotonic() < deadline:
            time.sleep(0.1)
            pids = [int(path.read_text()) for path in tmp_path.glob('pid*') if path.read_text()]
        assert len(pids) == 2, 'the parts did not start'
        runner.send_signal(signal.SIGTERM)
        time.sleep(0.5)   # the first part is ending on its SIGINT
        runner.send_signal(signal.SIGTERM)
        output = runner.communicate(timeout=30)[0]
        print(output)
        assert runner.returncode == 130 and 'INTERRUPTED' in output
        assert [pid for pid in pids if os.path.exists('/proc/%d' % pid)] == []
    finally:
        if runner.poll() is None:
            runner.kill()
        for pid in pids:
            try:
                os.kill(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
