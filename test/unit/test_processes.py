"""tb3_harness.processes.Process: what it starts hears Ctrl+C as a terminal's command does."""
import signal
import sys
import time

from tb3_harness.processes import Process

BUSY_CORE = [sys.executable, '-c', 'print("busy", flush=True)\nwhile True: pass']


def test_a_process_started_with_sigint_ignored_still_ends_on_sigint(tmp_path):
    """A script started in the background (nohup, `make test &`, a CI runner)
    inherits SIGINT ignored, and python then sets no KeyboardInterrupt handler:
    the busy core of test_calibration.py outlived its SIGINT by 20 s so."""
    before = signal.signal(signal.SIGINT, signal.SIG_IGN)   # as a background job's children have it
    try:
        busy = Process('busy_core', BUSY_CORE, str(tmp_path))
    finally:
        signal.signal(signal.SIGINT, before)
    deadline = time.monotonic() + 30.0
    while 'busy' not in busy.output() and time.monotonic() < deadline:
        time.sleep(0.05)
    assert 'busy' in busy.output(), busy.describe()
    asked = time.monotonic()
    busy.stop(timeout=5.0)
    took = time.monotonic() - asked
    assert 'KeyboardInterrupt' in busy.output(), busy.describe()
    assert took < 5.0, 'ended %.1f s after SIGINT (SIGTERM came at 5 s)' % took
