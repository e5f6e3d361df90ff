from tb3_sim_nav.throttle import Throttle


class FakeClock(object):
    def __init__(self):
        self.now = 100.0

    def __call__(self):
        return self.now


def test_one_message_per_kind_per_period():
    clock = FakeClock()
    throttle = Throttle(5.0, clock)
    assert throttle.allow('non-finite')
    assert sum(throttle.allow('non-finite') for _ in range(1000)) == 0
    clock.now += 5.0
    assert throttle.allow('non-finite')


def test_a_flood_of_one_kind_does_not_hide_another():
    throttle = Throttle(5.0, FakeClock())
    assert throttle.allow('non-finite')
    assert not throttle.allow('non-finite')
    assert throttle.allow('linear.x')
    assert throttle.allow('angular.z')
