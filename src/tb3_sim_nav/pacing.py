"""Real-time pacing: how long to wait before simulating the next step.

A pure class with an injectable wall clock, so tests need neither time nor ROS.
"""
import time

#: Falling further behind than this (wall seconds) re-anchors the pacing
#: instead of racing to catch up, as Gazebo does when a step runs long.
MAX_LAG = 0.25


class Pacer(object):
    """Keeps simulated time at `factor` times wall time (0: as fast as possible)."""

    def __init__(self, factor, paused=False, wall_clock=time.monotonic, sleep=time.sleep):
        if not factor >= 0.0:
            raise ValueError('real-time factor must be >= 0, not %r' % (factor,))
        self.factor = float(factor)
        self.paused = paused
        self._wall_clock = wall_clock
        self._sleep = sleep
        self._anchor = None

    def _reanchor(self, sim_time):
        self._anchor = (self._wall_clock(), sim_time)

    def pause(self):
        self.paused = True

    def resume(self):
        self.paused = False
        self.restart()

    def restart(self):
        """Pace from the next step on as if starting afresh (after a pause or hold)."""
        self._anchor = None

    def set_factor(self, factor):
        self.__init__(factor, self.paused, self._wall_clock, self._sleep)

    def wait_until(self, sim_time):
        """Sleep until the wall clock is due for simulated time `sim_time` (s)."""
        if self.factor == 0.0:
            return
        if self._anchor is None:
            self._reanchor(sim_time)
            return
        wall_start, sim_start = self._anchor
        delay = wall_start + (sim_time - sim_start) / self.factor - self._wall_clock()
        if delay > 0.0:
            self._sleep(delay)
        elif delay < -MAX_LAG:
            self._reanchor(sim_time)


class Schedule(object):
    """Says which simulated instants (integer ns) a periodic output is due at.

    Due times stay on the grid 0, period, 2 period... so a rate that does not
    divide the physics rate still averages exactly `period`.
    """

    def __init__(self, period_ns):
        self.period_ns = int(period_ns)
        self.next_ns = 0

    def restart(self):
        """Due at the next step, as at start (time went back to zero: reset_simulation). Said, not
        guessed from the time: a reset within the first period looked like no reset, and the first
        scan after it came a period late at one factor and not at the other."""
        self.next_ns = 0

    def due(self, now_ns):
        if now_ns < self.next_ns:
            return False
        self.next_ns += self.period_ns
        if self.next_ns <= now_ns:  # time jumped ahead: restart the grid from now
            self.next_ns = now_ns + self.period_ns
        return True


class WallShare(object):
    """Lets work that may be skipped (a camera frame) take at most `share` of the wall time.

    After work that took `seconds`, the next may start only once the wall
    clock has run on by seconds * (1 - share) / share: at 0.5, as long again.
    """

    def __init__(self, share, wall_clock=time.monotonic):
        if not 0.0 < share <= 1.0:
            raise ValueError('a share of wall time must be in (0, 1], not %r' % (share,))
        self.share = share
        self._wall_clock = wall_clock
        self._ready_at = -float('inf')

    def allows(self):
        return self._wall_clock() >= self._ready_at

    def spent(self, seconds):
        self._ready_at = self._wall_clock() + seconds * (1.0 - self.share) / self.share
