"""At most one message of each kind per period, whatever arrives in between."""
import time


class Throttle(object):
    """Says whether a message of a kind may go out now (wall time)."""

    def __init__(self, period, clock=time.monotonic):
        self.period = period
        self._clock = clock
        self._last = {}

    def allow(self, kind):
        now = self._clock()
        last = self._last.get(kind)
        if last is not None and now - last < self.period:
            return False
        self._last[kind] = now
        return True
