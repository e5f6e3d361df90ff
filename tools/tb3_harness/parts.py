"""make test's parts, several at a time where the two cores allow it (tools/run_tests.sh).

A part is one command of `make test`: the unit tests, catkin_lint, a system
test file or a share of one, the rostests, the soak. Most of them wait on
the clock: a simulator at real time, a script driving it and a master keep
about a third of one core busy (doc/testing.md has what each part costs).
So parts run side by side, each taking the share of the machine it needs,
in SLOTS slots (3 by default):

  1  it mostly waits on real time;
  2  it keeps a core busy (the unit tests, runs as fast as possible, a build);
  3  it times wall seconds that a busy machine would stretch, or loads a
     core on purpose: it runs alone.

Whenever slots are free, the first waiting part in the plan's order that
fits in them starts: a part that needs more waits while smaller ones pass
it, and starts as soon as enough are free at once. Once every part of 2 or
3 slots has ended, the parts of 1 slot that are left run one more side by
side (TAIL_EXTRA): each keeps about a third of a core busy. So the plan puts the
parts that run alone first (the machine is empty at the start), then those
that keep a core busy, one after another beside the rostests, then the
rest, longest first, so that the last to end is a short one. Each
runs in a session of its own with TB3_RUN set to a tag of its own: what it
left running when it ends fails it (tb3_harness.leftovers). Its output goes
to its log and is shown whole when it ends, so that parts never interleave;
at the end come a table of every part's wall and CPU time and the lines
that say why a part failed, where a CI log's tail shows them.

    python3 -m tb3_harness.parts PLAN [LOG_DIR]

PLAN has one part a line, `SLOTS NAME COMMAND` (COMMAND runs in bash; a
line starting with # is a comment). The exit status is 0 only if every part
passed.
"""
import collections
import os
import re
import signal
import sys
import tempfile
import time

from . import leftovers
from .processes import Process

SLOTS = 3            # parts of slot 1 that run at once on 2 cores (see the module's docstring)
TAIL_EXTRA = 1       # slots added once only parts of 1 slot are left (not with 1 slot: one at a time)
POLL = 0.2           # wall s between looks at the running parts
WHY_LINES = 40       # lines of a failed part's output repeated at the end
_WHY = re.compile(r'^(FAILED|ERROR) |(Error|Exception)(: |$)|  MISSED$|FAILED: |^Summary: |LEFT RUNNING')
_ROSTEST_FAILURE = re.compile(r'\]\[(FAILURE|ERROR)\]')

Part = collections.namedtuple('Part', 'slots name command')


class PlanError(ValueError):
    """A plan line that is not `SLOTS NAME COMMAND`."""


def read_plan(text):
    """The Parts of a plan's text, in its order."""
    parts = []
    for number, line in enumerate(text.splitlines(), 1):
        if not line.strip() or line.lstrip().startswith('#'):
            continue
        fields = line.split(None, 2)
        if len(fields) < 3 or not fields[0].isdigit() or int(fields[0]) < 1:
            raise PlanError('plan line %d is not "SLOTS NAME COMMAND" with SLOTS >= 1: %r' % (number, line))
        if any(part.name == fields[1] for part in parts):
            raise PlanError('plan line %d: a second part named %s' % (number, fields[1]))
        parts.append(Part(int(fields[0]), fields[1], fields[2]))
    return parts


def why(output):
    """The lines of a failed part's output that say what failed: rostest's failure
    headers with the line after each, pytest's short summary, the exception line
    of each traceback, the soak's missed rows, processes left running."""
    lines = output.splitlines()
    picked = []
    for index, line in enumerate(lines):
        if _ROSTEST_FAILURE.search(line):
            picked += lines[index:index + 2]
    picked += [line for line in lines if _WHY.search(line)]
    return list(collections.OrderedDict.fromkeys(picked))[:WHY_LINES]


class Schedule(object):
    """Which parts may start: in the plan's order, each that fits in the free slots.

    Pure bookkeeping (no processes), so that the order can be tested alone."""

    def __init__(self, parts, slots=SLOTS):
        if slots < 1:
            raise ValueError('slots must be >= 1, not %r' % slots)
        self.slots = slots
        self.waiting = list(parts)
        self.running = []

    def need(self, part):
        return min(part.slots, self.slots)   # more than there are: alone

    def free(self):
        slots = self.slots
        if slots > 1 and all(part.slots == 1 for part in self.waiting + self.running):
            # The tail: waiting parts only (the last thirteen of make test: 0.38
            # of a core each on average, 2026-11-24), one more of them fits.
            slots += TAIL_EXTRA
        return slots - sum(self.need(part) for part in self.running)

    def next(self):
        """The part to start now, or None: the first in the plan's order that fits.
        A part that does not fit yet lets later ones pass it, so that no slot idles
        while it waits; it starts when enough slots are free at once."""
        for part in self.waiting:
            if self.need(part) <= self.free():
                self.waiting.remove(part)
                self.running.append(part)
                return part
        return None

    def ended(self, part):
        self.running.remove(part)

    def done(self):
        return not self.waiting and not self.running


def _say(message):
    print(message, flush=True)


def minutes(seconds):
    return '%d:%02d' % divmod(int(round(seconds)), 60)


class Runner(object):
    """Runs a plan's parts as the Schedule allows; results in `self.results`."""

    def __init__(self, parts, log_dir, slots=SLOTS):
        self.schedule = Schedule(parts, slots)
        self.log_dir = log_dir
        os.makedirs(log_dir, exist_ok=True)
        self.tag = 'tb3_test_%d' % os.getpid()
        self.started = {}   # name -> (Process, wall start)
        self.cpu = {}       # name -> CPU s of the part's process tree, once reaped here
        self.results = []   # (part, start s, took s, CPU s or None, failures: list of str)
        self.t0 = time.monotonic()
        self.load = os.getloadavg()[0]

    def _start(self, part):
        environment = dict(os.environ, **{leftovers.TAG: '%s.%s' % (part.name, self.tag)})
        # pytest's temporary folders: one base of its own per part, as two pytest
        # processes that share one may clean each other's numbered folders away.
        environment['PYTEST_ADDOPTS'] = ('%s --basetemp=%s' % (
            environment.get('PYTEST_ADDOPTS', ''), os.path.join(self.log_dir, part.name + '.tmp'))).strip()
        process = Process(part.name, ['bash', '-c', part.command], self.log_dir, env=environment)
        self.started[part.name] = (process, time.monotonic())
        others = [other.name for other in self.schedule.running if other is not part]
        _say('== %s: started at %s (%d slot%s%s)' % (part.name, minutes(time.monotonic() - self.t0), part.slots,
                                                    '' if part.slots == 1 else 's',
                                                    ', beside ' + ', '.join(others) if others else ''))

    def _ended(self, part):
        """True once the part's command has ended: reaped here with wait4, which also
        tells the CPU time of its whole tree (each process counted by its waiting parent)."""
        process = self.started[part.name][0]
        if process.popen.returncode is None:
            pid, status, usage = os.wait4(process.pid, os.WNOHANG)
            if pid == 0:
                return False
            process.popen.returncode = os.waitstatus_to_exitcode(status)
            self.cpu[part.name] = usage.ru_utime + usage.ru_stime
        return True

    def _finish(self, part, took):
        """Its outcome (status, leftovers), output and time, once the slots are given on."""
        process, start = self.started.pop(part.name)
        failures = [] if process.popen.returncode == 0 else ['exit status %s' % process.popen.returncode]
        left = leftovers.check('%s.%s' % (part.name, self.tag), part.name)
        if left:
            failures.append('left %d process(es) running' % len(left))
            with open(process.log, 'a') as log:   # where `why` finds them
                log.write(''.join('LEFT RUNNING after %s: pid %d: %s\n' % (part.name, pid, command)
                                  for pid, command in left))
        self.results.append((part, start - self.t0, took, self.cpu.get(part.name), failures))
        _say('== %s: %s after %s' % (part.name, 'FAILED (%s)' % '; '.join(failures) if failures else 'passed',
                                      minutes(took)))
        sys.stdout.write(process.output(last=1 << 24))
        _say('== end of %s' % part.name)

    def _start_what_fits(self):
        part = self.schedule.next()
        while part is not None:
            self._start(part)
            part = self.schedule.next()

    def run(self):
        try:
            self._start_what_fits()
            while not self.schedule.done():
                time.sleep(POLL)
                ended = [(part, time.monotonic() - self.started[part.name][1])
                         for part in list(self.schedule.running) if self._ended(part)]
                for part, _ in ended:
                    self.schedule.ended(part)
                self._start_what_fits()   # before the leftovers checks, which may wait
                for part, took in ended:
                    self._finish(part, took)
        finally:
            # Interrupted: each part still running is stopped as Ctrl+C would. A second Ctrl+C or
            # SIGTERM meanwhile (a CI runner's stop repeats it) would end this loop and leave the
            # parts not yet stopped running on their own: they are ignored until every part is.
            previous = dict((sig, signal.signal(sig, signal.SIG_IGN)) for sig in (signal.SIGINT, signal.SIGTERM))
            try:
                for part in [part for part in self.schedule.running if part.name in self.started]:
                    self.started[part.name][0].stop()
                    self.schedule.ended(part)
                    self._finish(part, time.monotonic() - self.started[part.name][1])
            finally:
                for sig, handler in previous.items():
                    signal.signal(sig, handler)
        return self.results


def table(results, total, load=None):
    """The lines of the summary: each part's slots, start, wall and CPU time
    (its whole process tree's), and outcome, in start order."""
    lines = ['%-38s %5s %7s %7s %7s  %s' % ('part', 'slots', 'start', 'took', 'CPU', 'result')]
    for part, start, took, cpu, failures in sorted(results, key=lambda result: result[1]):
        lines.append('%-38s %5d %7s %7s %7s  %s' % (part.name, part.slots, minutes(start), minutes(took),
                                                     '-' if cpu is None else minutes(cpu),
                                                     'FAILED' if failures else 'passed'))
    cpu = sum(result[3] or 0.0 for result in results)
    lines.append('%-38s %5s %7s %7s %7s' % ('make test', '', '', minutes(total), minutes(cpu)))
    if load is not None:
        lines.append('%d cores; load average (1 min) %.1f at the start, %.1f at the end'
                     % (os.cpu_count(), load, os.getloadavg()[0]))
    return lines


def main(argv):
    if len(argv) not in (2, 3):
        sys.stderr.write('usage: python3 -m tb3_harness.parts PLAN [LOG_DIR]\n')
        return 2
    with open(argv[1]) as plan:
        parts = read_plan(plan.read())
    log_dir = argv[2] if len(argv) == 3 else tempfile.mkdtemp(prefix='tb3_test_')
    slots = int(os.environ.get('TB3_TEST_SLOTS', SLOTS))
    signal.signal(signal.SIGTERM, signal.default_int_handler)   # CI's stop: clean up as on Ctrl+C
    runner = Runner(parts, log_dir, slots)
    interrupted = False
    try:
        runner.run()
    except KeyboardInterrupt:
        interrupted = True
    total = time.monotonic() - runner.t0
    _say('\n'.join([''] + table(runner.results, total, runner.load)))
    failed = [(part, failures) for part, _, _, _, failures in runner.results if failures]
    for part, failures in failed:
        _say('== why %s failed (%s)' % (part.name, '; '.join(failures)))
        with open(os.path.join(log_dir, part.name + '.log'), errors='replace') as log:
            _say('\n'.join(why(log.read())))
    not_run = [part.name for part in runner.schedule.waiting]
    if interrupted:
        _say('INTERRUPTED; not run: %s' % (', '.join(not_run) or 'none'))
        return 130
    if failed:
        _say('FAILED: %s' % ' '.join(part.name for part, _ in failed))
        return 1
    _say('ALL PASSED')
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv))
