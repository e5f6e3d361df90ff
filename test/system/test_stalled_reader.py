"""A subscriber that stops reading costs only itself.

tb3_world.launch at real_time_factor 0, as the issue tried it, with two of
the user's readers, `rostopic echo /scan/header` and `rostopic echo
/imu/header` (each subscribes to the whole topic), suspended with SIGSTOP as
Ctrl+Z does, until the simulator says it drops messages for both (their
sockets' buffers are full) and STALL_AFTER_DROPS wall seconds more.
Meanwhile bare readers (tb3_harness's TcprosReader, which keep up) record
every message of /clock, /imu, /scan and /odom. Then:

- sim time advanced in every wall second of the stall, at no less than half
  its pace before it;
- the bare readers lost nothing: /clock has every 10 ms step, /imu, /scan
  and /odom every sequence number;
- after SIGCONT, each echo prints messages stamped within CURRENT_LAG of
  the sim time of the moment, within RESUME_WITHIN wall seconds.
"""
import os
import re
import signal
import struct
import threading
import time

from tb3_harness.measure import sim_uri
from tb3_harness.tcpros_reader import TcprosReader

from tb3_system_utils import wait_until

STEP_NS = 10000000            # one physics step (100 Hz)
STALL_AFTER_DROPS = 20.0      # wall s of stall after both readers are reported dropping
DROPS_WITHIN = 180.0          # wall s for the simulator to report them dropping
RESUME_WITHIN = 30.0          # wall s after SIGCONT for an echo to print current messages
CURRENT_LAG = 1.0             # wall s: how old (in sim time, at the pace measured) a current message may be
STAMP = re.compile(r'stamp: *\n +secs: (\d+)\n +nsecs: +(\d+)')


class Recording(object):
    """Every message of one topic from a bare reader: its first 12 bytes
    (a Clock's secs and nsecs; a Header's seq, secs and nsecs)."""

    def __init__(self, topic):
        self.topic = topic
        self._lock = threading.Lock()
        self.heads = []
        self.reader = TcprosReader(sim_uri, topic, keep=self._keep, caller_id='/tb3_test_reader')

    def _keep(self, body):
        with self._lock:
            self.heads.append(struct.unpack_from('<III', body.ljust(12, b'\0')))

    def clock_ns(self):
        with self._lock:
            return [secs * 1000000000 + nsecs for secs, nsecs, _ in self.heads]

    def seqs(self):
        with self._lock:
            return [seq for seq, _, _ in self.heads]

    def now(self):
        """The newest /clock (sim s), for the /clock recording."""
        with self._lock:
            return self.heads[-1][0] + self.heads[-1][1] * 1e-9 if self.heads else 0.0


def newest_stamp(log):
    with open(log, errors='replace') as text:
        stamps = STAMP.findall(text.read())
    return int(stamps[-1][0]) + int(stamps[-1][1]) * 1e-9 if stamps else None


def test_a_suspended_reader_costs_only_itself(ros_port, processes):
    processes.start_master('roscore', ros_port)
    sim = processes.start('sim', ['roslaunch', '--wait', 'tb3_sim_bringup', 'tb3_world.launch',
                                  'real_time_factor:=0'])
    recordings = dict((topic, Recording(topic)) for topic in ('/clock', '/imu', '/scan', '/odom'))
    clock = recordings['/clock']
    try:
        assert wait_until(lambda: clock.now() > 1.0 or not sim.running(), 60.0), 'no /clock'
        echoes = dict((topic, processes.start('echo_' + topic[1:], ['rostopic', 'echo', topic + '/header'],
                                               env=dict(os.environ, PYTHONUNBUFFERED='1')))
                      for topic in ('/scan', '/imu'))
        for topic, echo in echoes.items():
            assert wait_until(lambda: newest_stamp(echo.log) is not None, 60.0), \
                'rostopic echo %s printed nothing' % topic
        start_wall, start_sim = time.monotonic(), clock.now()
        time.sleep(5.0)
        pace = (clock.now() - start_sim) / (time.monotonic() - start_wall)

        for echo in echoes.values():
            echo.signal_group(signal.SIGSTOP)
        samples = [(time.monotonic(), clock.now())]

        def dropping(topic):
            with open(sim.log, errors='replace') as log:
                return re.search(r'%s: subscriber /rostopic_\S+ does not keep up' % topic, log.read())

        deadline, drops_seen = time.monotonic() + DROPS_WITHIN, None
        while drops_seen is None or time.monotonic() < drops_seen + STALL_AFTER_DROPS:
            time.sleep(1.0)
            samples.append((time.monotonic(), clock.now()))
            if drops_seen is None and dropping('/scan') and dropping('/imu'):
                drops_seen = time.monotonic()
            assert drops_seen or time.monotonic() < deadline, \
                'no warning of dropped messages for both suspended readers within %.0f s; sim time stood ' \
                'still for %d of those wall seconds' % (DROPS_WITHIN, sum(1 for a, b in zip(samples, samples[1:])
                                                                          if b[1] == a[1]))
        stall_pace = (samples[-1][1] - samples[0][1]) / (samples[-1][0] - samples[0][0])
        slowest = min((b[1] - a[1]) / (b[0] - a[0]) for a, b in zip(samples, samples[1:]))

        for echo in echoes.values():
            echo.signal_group(signal.SIGCONT)
        lags = {}
        for topic, echo in echoes.items():
            def current():
                stamp = newest_stamp(echo.log)
                lags[topic] = (clock.now() - stamp) / pace if stamp is not None else None
                return lags[topic] is not None and lags[topic] < CURRENT_LAG
            wait_until(current, RESUME_WITHIN)
    finally:
        for recording in recordings.values():
            recording.reader.close()
    print('MEASURED stalled_reader: pace before %.1f, during the stall %.1f (slowest second %.1f) sim s per wall s; '
          'stall %.0f wall s; echo lags after SIGCONT (wall s) %s; messages recorded %s'
          % (pace, stall_pace, slowest, samples[-1][0] - samples[0][0], lags,
             dict((topic, len(recording.heads)) for topic, recording in recordings.items())))

    assert slowest > 0.0, 'sim time stood still for a second of the stall'
    assert stall_pace >= 0.5 * pace
    # From the third: rospy may send the latched tick again to a subscriber that
    # has just connected (a repeat, never an older one).
    ticks = clock.clock_ns()[2:]
    gaps = [(a, b) for a, b in zip(ticks, ticks[1:]) if b - a != STEP_NS]
    assert not gaps, '/clock skipped or repeated steps: %s' % gaps[:5]
    for topic in ('/imu', '/scan', '/odom'):
        seqs = recordings[topic].seqs()
        missing = [(a, b) for a, b in zip(seqs, seqs[1:]) if b != a + 1]
        assert len(seqs) > 10 and not missing, '%s: %d messages, lost after seq %s' % (topic, len(seqs), missing[:5])
    for topic, lag in lags.items():
        assert lag is not None and lag < CURRENT_LAG, \
            'rostopic echo %s: newest message %s wall s old %.0f s after SIGCONT' % (topic, lag, RESUME_WITHIN)

