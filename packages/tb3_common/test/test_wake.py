"""A node's notice to the simulator's lockstep (tb3_common.wake) and how its Life keeps it."""
import os
import threading
import time

import pytest
import rospy
import rospy.rostime

from tb3_common import wake
from tb3_common.ros.lifecycle import Life, SimAlarm


def test_the_reader_sees_what_the_node_writes_and_acting_once_it_is_gone(tmp_path):
    notice = wake.Notice(str(tmp_path))
    reader = wake.Reader(os.getpid(), str(tmp_path))
    assert reader.next_wake() == wake.ACTING
    notice.write(12345678901)
    assert reader.next_wake() == 12345678901
    notice.write(wake.NEVER)
    assert reader.next_wake() == wake.NEVER
    notice.close()
    assert not os.listdir(str(tmp_path))
    assert wake.Reader(os.getpid(), str(tmp_path)).next_wake() == wake.ACTING   # no file: wait at every tick


def test_a_file_left_by_an_earlier_process_with_the_same_pid_is_not_read(tmp_path):
    """A node killed outright leaves its file: a later process with its PID started at another time."""
    own = wake.path_of(os.getpid(), str(tmp_path))
    started = int(own.rsplit('_', 1)[1])
    stale = own.rsplit('_', 1)[0] + '_%d' % (started - 1)
    with open(stale, 'wb') as stream:
        stream.write(wake.NEVER.to_bytes(8, 'little', signed=True))
    assert wake.Reader(os.getpid(), str(tmp_path)).next_wake() == wake.ACTING
    assert wake.path_of(1 << 30, str(tmp_path)) is None   # no such process


@pytest.fixture
def sim_time():
    """rospy's clock on sim time, set by the test in ns (as /clock would), back to unset afterwards."""
    rospy.rostime.set_rostime_initialized(True)
    rospy.rostime._set_rostime(rospy.Time(10, 0))
    yield lambda ns: rospy.rostime._set_rostime(rospy.Time(0, ns))
    rospy.rostime._rostime_current = None
    rospy.rostime.set_rostime_initialized(False)


def _wait_for(predicate, timeout=5.0):
    end = time.monotonic() + timeout
    while not predicate() and time.monotonic() < end:
        time.sleep(0.001)
    return predicate()


def test_the_notice_is_the_earliest_wake_of_the_threads_that_wait_and_acting_while_one_acts(tmp_path, sim_time):
    notice = wake.Notice(str(tmp_path))
    reader = wake.Reader(os.getpid(), str(tmp_path))
    life = Life(notice)
    released = threading.Event()

    def data_only():
        with life.waiting_for_data():
            released.wait(10.0)

    waiter = threading.Thread(target=data_only)
    waiter.start()
    assert _wait_for(lambda: reader.next_wake() == wake.NEVER)
    # A control loop's sleep: sleep_sim's own end, in ns, as its `now >= end` compares.
    sleeper = threading.Thread(target=life.sleep_sim, args=(0.3,))
    sleeper.start()
    assert _wait_for(lambda: reader.next_wake() == 10300000000)
    sim_time(10290000000)
    time.sleep(0.05)
    assert sleeper.is_alive() and reader.next_wake() == 10300000000
    sim_time(10300000000)
    sleeper.join(5.0)
    # Awake, it may act at any tick until it sleeps again.
    assert not sleeper.is_alive() and reader.next_wake() == wake.ACTING
    released.set()
    waiter.join(5.0)
    life.close_notice()
    assert not os.listdir(str(tmp_path))


def test_a_life_without_a_notice_writes_nothing_and_sleeps_as_before(sim_time):
    life = Life()
    sleeper = threading.Thread(target=life.sleep_sim, args=(0.2,))
    sleeper.start()
    time.sleep(0.05)
    sim_time(10200000000)
    sleeper.join(5.0)
    assert not sleeper.is_alive()
    with life.waiting_for_data():
        pass


class CountedCondition(threading.Condition):
    def __init__(self):
        super(CountedCondition, self).__init__()
        self.notices = 0

    def notify_all(self):
        self.notices += 1
        super(CountedCondition, self).notify_all()


def test_a_clock_alarm_wakes_a_sleeper_at_its_end_and_when_time_goes_back_not_at_every_tick(sim_time):
    """rospy would wake it at each /clock tick: nine of ten for nothing in a 10 Hz loop."""
    from rosgraph_msgs.msg import Clock
    life = Life()
    life._alarm = alarm = SimAlarm()
    alarm.condition = CountedCondition()

    def tick(ns):  # what rospy's /clock subscription does: the time, then the alarm's callback
        sim_time(ns)
        alarm.on_clock(Clock(rospy.Time(0, ns)))

    ends = []
    sleeper = threading.Thread(target=lambda: ends.append(life.sleep_sim(0.1)))
    sleeper.start()
    assert _wait_for(lambda: alarm.ends)
    for ns in range(10010000000, 10100000000, 10000000):  # 9 ticks before its end
        tick(ns)
    assert alarm.condition.notices == 0 and sleeper.is_alive()
    tick(10100000000)
    sleeper.join(5.0)
    assert not sleeper.is_alive() and ends == [True] and alarm.condition.notices == 1 and not alarm.ends
    # A reset: the clock goes back, and a sleeper wakes at once.
    sleeper = threading.Thread(target=lambda: ends.append(life.sleep_sim(5.0)))
    sleeper.start()
    assert _wait_for(lambda: alarm.ends)
    tick(20000000)
    sleeper.join(5.0)
    assert not sleeper.is_alive() and ends == [True, True] and alarm.condition.notices == 2


def test_one_notice_for_the_threads_awaiting_only_while_every_thread_awaits():
    assert wake.combined([wake.AWAITING, wake.AWAITING]) == wake.AWAITING
    # A thread waiting for any data is woken by the stored topics too; one asleep until a time wakes then.
    assert wake.combined([wake.AWAITING, wake.NEVER]) == wake.NEVER
    assert wake.combined([wake.AWAITING, 5]) == 5
    assert wake.combined([wake.NEVER, 5, wake.ACTING]) == wake.ACTING


def test_awaiting_is_said_only_by_a_node_that_declared_the_topics_it_stores(tmp_path):
    notice = wake.Notice(str(tmp_path))
    reader = wake.Reader(os.getpid(), str(tmp_path))
    life = Life(notice)
    with life.waiting_for_data(except_stored=True):
        assert reader.next_wake() == wake.NEVER   # nothing declared: any data wakes it
    life.stores(['/odom', '/tb3_1/odom'])
    with life.waiting_for_data(except_stored=True):
        assert reader.next_wake() == wake.AWAITING
        assert reader.stored() == frozenset(['/odom', '/tb3_1/odom'])
    assert reader.next_wake() == wake.ACTING
    with life.waiting_for_data():   # waiting for odometry: now it wakes the node
        assert reader.next_wake() == wake.NEVER
    life.close_notice()
    assert wake.Reader(os.getpid(), str(tmp_path)).stored() == frozenset()


def test_a_thread_that_ended_does_not_keep_the_node_acting(tmp_path):
    notice = wake.Notice(str(tmp_path))
    reader = wake.Reader(os.getpid(), str(tmp_path))
    life = Life(notice)

    def waits_once():
        with life.waiting_for_data():
            pass
    worker = threading.Thread(target=waits_once)
    worker.start()
    worker.join(5.0)
    with life.waiting_for_data():
        assert reader.next_wake() == wake.NEVER
    life.close_notice()
