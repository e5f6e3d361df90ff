"""Real-time pacing and output schedules, on a fake wall clock (no real time passes)."""
import math

import pytest

from tb3_sim_nav.pacing import MAX_LAG, Pacer, Schedule, WallShare

DT = 1.0 / 200   # sim seconds per physics step
COMPUTE = 0.001  # wall seconds one physics step takes


class FakeWall(object):
    """A wall clock that only moves when slept on or told to."""

    def __init__(self, start=1000.0):
        self.now = start
        self.sleeps = []

    def clock(self):
        return self.now

    def sleep(self, seconds):
        assert seconds > 0.0
        self.sleeps.append(seconds)
        self.now += seconds


def pacer(factor, wall, **kwargs):
    return Pacer(factor, wall_clock=wall.clock, sleep=wall.sleep, **kwargs)


def run_steps(pace, wall, first, count, compute=COMPUTE):
    """Steps first..first+count-1 as the node's step loop does; the sleep (or None) before each."""
    slept = []
    for step in range(first, first + count):
        before = len(wall.sleeps)
        pace.wait_until(step * DT)
        slept.append(wall.sleeps[before] if len(wall.sleeps) > before else None)
        wall.now += compute
    return slept


@pytest.mark.parametrize('factor', [1.0, 2.0, 0.5])
def test_sim_time_tracks_wall_time_times_factor(factor):
    wall = FakeWall()
    pace = pacer(factor, wall)
    start = wall.now
    slept = run_steps(pace, wall, 1, 1000)
    assert slept[0] is None  # the first call only anchors
    assert slept[1:] == pytest.approx([DT / factor - COMPUTE] * 999, abs=1e-9)
    # Just before step 1000 ran, the wall had advanced (1000 - 1) steps' worth of sim time / factor.
    assert wall.now - COMPUTE - start == pytest.approx(999 * DT / factor, abs=1e-9)


def test_factor_two_sleeps_half_as_long_as_factor_one():
    walls = {factor: FakeWall() for factor in (1.0, 2.0)}
    for factor, wall in walls.items():
        run_steps(pacer(factor, wall), wall, 1, 400, compute=0.0)
    assert sum(walls[2.0].sleeps) == pytest.approx(sum(walls[1.0].sleeps) / 2, abs=1e-9)
    assert sum(walls[1.0].sleeps) == pytest.approx(399 * DT, abs=1e-9)


def test_factor_zero_never_sleeps():
    wall = FakeWall()
    run_steps(pacer(0.0, wall), wall, 1, 2000, compute=0.0)
    assert wall.sleeps == []


def test_small_lag_is_caught_up():
    wall = FakeWall()
    pace = pacer(1.0, wall)
    start = wall.now
    run_steps(pace, wall, 1, 10)
    wall.now += MAX_LAG / 2  # a hiccup shorter than MAX_LAG
    slept = run_steps(pace, wall, 11, 100)
    assert slept[0] is None
    # ...and the pacing is back on its original grid: no wall time lost.
    assert wall.now - COMPUTE - start == pytest.approx(109 * DT, abs=1e-9)


def test_lag_beyond_max_lag_reanchors_instead_of_bursting():
    wall = FakeWall()
    pace = pacer(1.0, wall)
    start = wall.now
    run_steps(pace, wall, 1, 10)
    wall.now += 4 * MAX_LAG  # a long stall
    slept = run_steps(pace, wall, 11, 100)
    assert slept[0] is None  # re-anchors on the late step...
    assert slept[1:] == pytest.approx([DT - COMPUTE] * 99, abs=1e-9)  # ...then paces normally
    # Step 10 ran at start + 9 DT; step 11 right after it and the stall; then 99 paced steps.
    assert wall.now - COMPUTE - start == pytest.approx(9 * DT + COMPUTE + 4 * MAX_LAG + 99 * DT, abs=1e-9)


def test_pause_and_resume_reanchor():
    wall = FakeWall()
    pace = pacer(1.0, wall)
    start = wall.now
    run_steps(pace, wall, 1, 10)
    pace.pause()
    assert pace.paused
    wall.now += MAX_LAG / 2  # paused for less than MAX_LAG: only re-anchoring avoids a burst
    pace.resume()
    assert not pace.paused
    slept = run_steps(pace, wall, 11, 100)
    assert slept[0] is None
    assert slept[1:] == pytest.approx([DT - COMPUTE] * 99, abs=1e-9)
    # Step 10 ran at start + 9 DT; step 11 right after it and the pause; then 99 paced steps.
    assert wall.now - COMPUTE - start == pytest.approx(9 * DT + COMPUTE + MAX_LAG / 2 + 99 * DT, abs=1e-9)


def test_paused_flag_from_constructor():
    assert Pacer(1.0, paused=True).paused
    assert not Pacer(1.0).paused


def test_set_factor_changes_pace_and_keeps_paused_state():
    wall = FakeWall()
    pace = pacer(1.0, wall)
    run_steps(pace, wall, 1, 10)
    pace.pause()
    pace.set_factor(4.0)
    assert pace.paused and pace.factor == 4.0
    pace.resume()
    slept = run_steps(pace, wall, 11, 50)
    assert slept[1:] == pytest.approx([DT / 4.0 - COMPUTE] * 49, abs=1e-9)


@pytest.mark.parametrize('factor', [-1.0, -1e-9, math.nan])
def test_bad_factor_is_refused(factor):
    with pytest.raises(ValueError):
        Pacer(factor)


# --- Schedule ------------------------------------------------------------------

STEP_NS = 5000000  # 200 Hz


def due_steps(schedule, steps):
    """The steps (numbers of physics steps since 0) at which `schedule` fires."""
    return [step for step in steps if schedule.due(step * STEP_NS)]


def test_schedule_fires_at_the_first_step():
    assert Schedule(round(1e9 / 30)).due(STEP_NS)


@pytest.mark.parametrize('rate', [30, 7, 60, 1, 200])
def test_schedule_gives_n_publications_in_n_periods(rate):
    schedule = Schedule(round(1e9 / rate))
    due_steps(schedule, range(1, 2001))                       # first 10 s
    assert len(due_steps(schedule, range(2001, 4001))) == 10 * rate    # next 10 s
    assert len(due_steps(schedule, range(4001, 24001))) == 100 * rate  # next 100 s


def test_schedule_30hz_on_200hz_spacing_stays_within_one_step():
    fired = due_steps(Schedule(round(1e9 / 30)), range(1, 20001))
    gaps = {later - earlier for earlier, later in zip(fired, fired[1:])}
    assert gaps == {6, 7}  # 30 ms or 35 ms: 33.3 ms on average


def test_schedule_recovers_after_time_jump_forward():
    schedule = Schedule(round(1e9 / 30))
    due_steps(schedule, range(1, 201))
    assert len(due_steps(schedule, range(20001, 20201))) == 30


@pytest.mark.parametrize('steps_before', [1, 3, 2000])
def test_schedule_restarted_fires_at_the_first_step_again(steps_before):
    """After reset_simulation (time back to 0), as after a start: also when the reset came within
    the first period, which a schedule cannot tell from the time alone (one step, then a reset)."""
    schedule = Schedule(round(1e9 / 5))
    due_steps(schedule, range(1, 1 + steps_before))
    schedule.restart()
    assert due_steps(schedule, range(1, 201)) == due_steps(Schedule(round(1e9 / 5)), range(1, 201))
    assert due_steps(Schedule(round(1e9 / 5)), range(1, 201))[:1] == [1]


def frames_rendered(cost, frames=150, rate=15.0, share=0.5):
    """(frames rendered, wall seconds taken) of `frames` camera frames due at `rate` (Hz
    of sim time, paced at real time) when each costs `cost` wall seconds and the
    camera may take `share` of the wall time."""
    wall = FakeWall()
    budget = WallShare(share, wall_clock=wall.clock)
    rendered = 0
    for frame in range(frames):
        wall.now = max(wall.now, 1000.0 + frame / rate)  # paced: wait for the frame's time
        if budget.allows():
            wall.now += cost
            budget.spent(cost)
            rendered += 1
    return rendered, wall.now - 1000.0


def test_a_camera_that_has_time_renders_every_frame():
    assert frames_rendered(0.030) == (150, pytest.approx(10.0, abs=0.1))  # 30 ms of every 67 ms


def test_a_camera_short_of_time_drops_frames_to_keep_to_its_share_of_the_wall_time():
    # 0.5 s a frame (llvmpipe on a loaded machine): one frame a second, and the world keeps real time.
    rendered, took = frames_rendered(0.5)
    assert rendered == 10 and took == pytest.approx(10.0, abs=0.5)
    rendered, took = frames_rendered(0.1, share=0.25)
    assert rendered * 0.1 == pytest.approx(0.25 * took, abs=0.1)


def test_a_wall_share_must_be_a_share():
    for share in (0.0, -0.5, 1.5, math.nan):
        with pytest.raises(ValueError, match='share'):
            WallShare(share)
