"""`make repeat`: one system test file run N times in a row beside busy cores, and a table.

Run inside `source setup.bash`. Starts --busy programs that each keep a core
busy (`python3 -c 'while True: pass'`), then runs `python3 -m pytest -q -s
-p no:cacheprovider FILE [-k EXPR]` in the repo's root --runs times, one
after another, each with a TB3_RUN tag of its own (tb3_harness.leftovers): a
process a run left running fails it and is ended. A run that takes longer than
--timeout is stopped (SIGINT to its process group, as Ctrl+C would) and fails.
Each run's output goes to LOG_DIR/run_NN.log. The busy cores are stopped after
the last run, also on a failure, Ctrl+C or SIGTERM.

The table (also LOG_DIR/table.txt): a row per run (passed or FAILED, wall
time, why it failed), then a row per figure the runs printed (`FIGURE name
value worse unit` lines, tb3_harness.report.figure): the median of every
value printed, the worst of them, and in how many runs it appeared. Exit
status 0 only if every run passed. What we run before calling a test stable:

    python3 tools/repeat.py test/system/test_navigation.py --runs 20 [--busy 1] [-k EXPR] [--log-dir DIR]
"""
import argparse
import collections
import datetime
import math
import os
import platform
import re
import signal
import statistics
import sys
import tempfile
import time

from tb3_harness import leftovers
from tb3_harness.parts import minutes, why
from tb3_harness.processes import Process, say

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BUSY_CORE = [sys.executable, '-c', 'while True: pass']
BUSY_GRACE = 5.0   # wall s a busy core has to end after each signal
FIGURE = re.compile(r'(?<!\w)FIGURE (\S+) ([-+]?(?:\d+(?:\.\d*)?(?:e[-+]?\d+)?|nan|inf)) (max|min)(?: (\S+))?[ \t]*$',
                    re.M)

Figure = collections.namedtuple('Figure', 'name value worse unit')
Run = collections.namedtuple('Run', 'number passed seconds note figures')


def parse_figures(output):
    """The Figures of a run's output, in order (a line may start with pytest's progress dots)."""
    return [Figure(name, float(value), worse, unit or '') for name, value, worse, unit in FIGURE.findall(output)]


def failure_line(output):
    """Why a run failed: pytest's first FAILED or ERROR line (with the first `E ` line of the tracebacks
    when the terminal's width left the message out), else the first line `why` picks."""
    picked = why(output)
    failed = [line for line in picked if line.startswith(('FAILED ', 'ERROR '))]
    if not failed:
        return picked[0] if picked else ''
    errors = [line[1:].strip() for line in output.splitlines() if line.startswith('E   ')]
    return failed[0] if ' - ' in failed[0] or not errors else failed[0] + ' - ' + errors[0]


def figure_rows(runs):
    """(name, unit, worse, median, worst, runs it appeared in) per figure name, in order of first appearance;
    NaN, a figure that could not be measured, is the worst of all."""
    values, seen = collections.OrderedDict(), collections.defaultdict(set)
    for run in runs:
        for figure in run.figures:
            key = (figure.name, figure.unit, figure.worse)
            values.setdefault(key, []).append(figure.value)
            seen[key].add(run.number)
    rows = []
    for key, numbers in values.items():
        finite = [number for number in numbers if not math.isnan(number)]
        worst = (max if key[2] == 'max' else min)(finite) if len(finite) == len(numbers) else math.nan
        rows.append(key + (statistics.median(finite) if finite else math.nan, worst, len(seen[key])))
    return rows


def table(header, runs):
    """The lines of the table: the header, a row per run, a row per figure, the count."""
    lines = [header, '', '%4s  %-7s %6s  %s' % ('run', 'result', 'wall', 'why it failed')]
    for run in runs:
        lines.append(('%4d  %-7s %6s  %s' % (run.number, 'passed' if run.passed else 'FAILED',
                                             minutes(run.seconds), run.note)).rstrip())
    rows = figure_rows(runs)
    if rows:
        lines += ['', '%-36s %-6s %-5s %10s %10s  %s' % ('figure', 'unit', 'worse', 'median', 'worst', 'runs')]
        lines += ['%-36s %-6s %-5s %10.6g %10.6g  %d/%d' % (row + (len(runs),)) for row in rows]
    passed = sum(run.passed for run in runs)
    return lines + ['', '%d passed, %d failed' % (passed, len(runs) - passed)]


def run_once(number, args, log_dir):
    """One run of the file, timed, under a TB3_RUN tag of its own: what it leaves running fails it."""
    name = 'run_%02d' % number
    command = [sys.executable, '-m', 'pytest', '-q', '-s', '-p', 'no:cacheprovider', os.path.abspath(args.file)]
    with leftovers.Guard(name) as guard:
        # Its temporary files beside its log (pytest's default base is shared with every other pytest).
        environment = dict(os.environ, PYTEST_ADDOPTS=('%s --basetemp=%s' % (
            os.environ.get('PYTEST_ADDOPTS', ''), os.path.join(log_dir, name + '.tmp'))).strip())
        start = time.monotonic()
        process = Process(name, command + (['-k', args.k] if args.k else []), log_dir, cwd=ROOT, env=environment)
        try:
            status = process.wait(args.timeout)
        finally:
            if process.running():   # timed out, or Ctrl+C here
                process.stop()
        seconds = time.monotonic() - start
    output = process.output(last=1 << 30)
    notes = [] if status == 0 else ['timed out after %.0f s' % args.timeout if status is None
                                    else failure_line(output) or 'exit status %s' % status]
    if guard.left:
        notes.append('left %d process(es) running: %s' % (len(guard.left), ', '.join(c for _, c in guard.left)))
    return Run(number, not notes, seconds, '; '.join(notes), parse_figures(output))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('file', help='a pytest file, e.g. test/system/test_navigation.py')
    parser.add_argument('--runs', type=int, default=20, help='runs, one after another (default 20)')
    parser.add_argument('--busy', type=int, default=1, help='programs keeping a core busy meanwhile (default 1)')
    parser.add_argument('-k', metavar='EXPR', help="pytest's -k: the file's tests to run")
    parser.add_argument('--timeout', type=float, default=1800.0, help='wall s a run may take (default 1800)')
    parser.add_argument('--log-dir', help='where the logs and table.txt go (default: a new temporary folder)')
    args = parser.parse_args(argv)
    log_dir = args.log_dir or tempfile.mkdtemp(prefix='tb3_repeat_')
    os.makedirs(log_dir, exist_ok=True)
    signal.signal(signal.SIGTERM, signal.default_int_handler)   # a stop from outside: clean up as on Ctrl+C
    header = '%s%s: %d runs beside %d busy core(s); %s, %d CPUs; %s' % (
        args.file, ' -k %r' % args.k if args.k else '', args.runs, args.busy,
        platform.processor() or platform.machine(), os.cpu_count(), datetime.datetime.now().strftime('%Y-%m-%d %H:%M'))
    say('repeat %s; logs in %s' % (header, log_dir))
    busy, runs, interrupted = [], [], False
    try:
        for index in range(args.busy):
            busy.append(Process('busy_%d' % index, BUSY_CORE, log_dir, die_with_parent=True))
        say('busy cores: %s' % (', '.join('pid %d' % process.pid for process in busy) or 'none'))
        for number in range(1, args.runs + 1):
            run = run_once(number, args, log_dir)
            runs.append(run)
            say('run %d of %d: %s after %s%s' % (number, args.runs, 'passed' if run.passed else 'FAILED',
                                               minutes(run.seconds), ': ' + run.note if run.note else ''))
    except KeyboardInterrupt:
        interrupted = True
    finally:
        for process in busy:
            process.stop(timeout=BUSY_GRACE)
    text = '\n'.join(table(header, runs) + (['INTERRUPTED after %d run(s)' % len(runs)] if interrupted else []))
    print('\n' + text, flush=True)
    with open(os.path.join(log_dir, 'table.txt'), 'w') as stream:
        stream.write(text + '\n')
    if interrupted:
        return 130
    return 0 if runs and all(run.passed for run in runs) else 1


if __name__ == '__main__':
    sys.exit(leftovers.run('make repeat', main))
