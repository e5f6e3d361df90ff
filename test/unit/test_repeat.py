"""tools/repeat.py: FIGURE lines, their parsing and the table, and one real run of the tool."""
import importlib.util
import math
import os
import re
import subprocess
import sys
import time

import pytest

from tb3_harness.report import figure

from conftest import REPO

_SPEC = importlib.util.spec_from_file_location('repeat', str(REPO / 'tools' / 'repeat.py'))
repeat = importlib.util.module_from_spec(_SPEC)   # the tool as a module, tools/ left off sys.path
_SPEC.loader.exec_module(repeat)

PYTEST_OUTPUT = """FIGURE goal_xy_error 0.0123 max m
.FIGURE goal_clearance 0.1 min m
FIGURE count 3 max
F
=========================== short test summary info ============================
FAILED test/system/test_x.py::test_b - AssertionError: 0.2 off
1 failed, 1 passed in 2.00s
"""


def test_a_figure_is_one_line_name_value_worse_unit(capsys):
    figure('goal_xy_error', 0.0123456789, 'max', 'm')
    figure('goal_clearance', 0.1, worse='min', unit='m')
    figure('goals', 4)
    assert capsys.readouterr().out == ('FIGURE goal_xy_error 0.0123457 max m\nFIGURE goal_clearance 0.1 min m\n'
                                       'FIGURE goals 4 max\n')


@pytest.mark.parametrize('call', [('a name', 1.0), ('name', 1.0, 'worst'), ('name', 1.0, 'max', 'm s'), ('', 1.0)])
def test_a_figure_that_could_not_be_read_back_is_refused(call):
    with pytest.raises(ValueError):
        figure(*call)


def test_figures_are_read_also_after_pytest_progress_dots():
    assert repeat.parse_figures(PYTEST_OUTPUT) == [
        ('goal_xy_error', 0.0123, 'max', 'm'), ('goal_clearance', 0.1, 'min', 'm'), ('count', 3.0, 'max', '')]
    assert repeat.parse_figures('no FIGURE here\nMY_FIGURE a 1 max\nFIGURE a b max\nFIGURE a 1 max m s\n') == []
    odd = repeat.parse_figures('FIGURE a nan min\nFIGURE b -1.5e+06 max\n')
    assert math.isnan(odd[0].value) and odd[1] == ('b', -1.5e6, 'max', '')


def test_a_failed_run_is_told_by_its_first_failure_line():
    assert repeat.failure_line(PYTEST_OUTPUT) == 'FAILED test/system/test_x.py::test_b - AssertionError: 0.2 off'
    trimmed = 'E       AssertionError: too far\n    \nFAILED test/system/test_x.py::test_a_long_name\n'
    assert repeat.failure_line(trimmed) == 'FAILED test/system/test_x.py::test_a_long_name - AssertionError: too far'
    assert repeat.failure_line('nothing to see\n') == ''


def run(number, passed, *figures, seconds=61.0, note=''):
    return repeat.Run(number, passed, seconds, note, [repeat.Figure(*f) for f in figures])


def test_each_figure_keeps_its_worst_and_median_over_the_runs():
    runs = [run(1, True, ('error', 0.01, 'max', 'm'), ('error', 0.03, 'max', 'm'), ('clearance', 0.2, 'min', 'm')),
            run(2, True, ('error', 0.02, 'max', 'm'), ('clearance', 0.1, 'min', 'm')),
            run(3, False, ('clearance', 0.3, 'min', 'm'))]
    assert repeat.figure_rows(runs) == [('error', 'm', 'max', 0.02, 0.03, 2),
                                        ('clearance', 'm', 'min', 0.2, 0.1, 3)]
    nan = repeat.figure_rows([run(1, True, ('share', math.nan, 'min', '%')), run(2, True, ('share', 90, 'min', '%'))])
    assert math.isnan(nan[0][4]) and nan[0][3] == 90


def test_the_table_has_a_row_per_run_and_per_figure_and_the_count():
    runs = [run(1, True, ('error', 0.01, 'max', 'm')),
            run(2, False, ('error', 0.03, 'max', 'm'), seconds=5.0, note='FAILED test_x.py::test_b - off')]
    lines = repeat.table('HEADER', runs)
    assert lines[0] == 'HEADER'
    assert re.match(r' +1 +passed +1:01$', lines[3])
    assert re.match(r' +2 +FAILED +0:05 +FAILED test_x.py::test_b - off$', lines[4])
    assert lines[7].split() == ['error', 'm', 'max', '0.02', '0.03', '2/2']
    assert lines[-1] == '1 passed, 1 failed'


THROWAWAY = '''import os
from tb3_harness.report import figure

COUNT = os.path.join(os.path.dirname(os.path.abspath(__file__)), 'runs')


def test_passes_once():
    runs = int(open(COUNT).read()) if os.path.exists(COUNT) else 0
    with open(COUNT, 'w') as stream:
        stream.write(str(runs + 1))
    figure('end_error', 0.1 * (runs + 1), 'max', 'm')
    assert runs == 0, 'the second run fails'
'''


def test_two_real_runs_one_passed_one_failed_and_no_busy_core_left(tmp_path):
    test_file = tmp_path / 'test_throwaway.py'
    test_file.write_text(THROWAWAY)
    logs = tmp_path / 'logs'
    tool = subprocess.run([sys.executable, str(REPO / 'tools' / 'repeat.py'), str(test_file), '--runs', '2',
                           '--busy', '1', '--log-dir', str(logs)], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                          universal_newlines=True, timeout=300)
    assert tool.returncode == 1, tool.stdout
    table = (logs / 'table.txt').read_text()
    assert table in tool.stdout
    assert '2 runs beside 1 busy core(s)' in table.splitlines()[0]
    assert re.search(r'^ +1 +passed +\d+:\d\d$', table, re.M), table
    assert re.search(r'^ +2 +FAILED +\d+:\d\d +FAILED .*test_passes_once - AssertionError: the second run fails',
                     table, re.M), table
    assert re.search(r'^end_error +m +max +0\.15 +0\.2 +2/2$', table, re.M), table
    assert table.rstrip().endswith('1 passed, 1 failed')
    assert {'busy_0.log', 'run_01.log', 'run_02.log'} <= set(os.listdir(logs))
    busy = [int(pid) for pid in re.findall(r'busy cores: pid (\d+)', tool.stdout)]
    assert len(busy) == 1
    deadline = time.monotonic() + 5.0   # the tool reaped it before it ended; gone, unless the pid was reused
    while os.path.exists('/proc/%d' % busy[0]) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert not os.path.exists('/proc/%d' % busy[0]) or 'while True' not in open('/proc/%d/cmdline' % busy[0]).read()
