"""The one parameter layer: one set of rules for every node's config (tb3_common.params)."""
import dataclasses
import math
from typing import Optional

import pytest

from tb3_common.params import (
    Checked,
    ParameterError,
    fail,
    frame_id,
    non_negative,
    number,
    one_of,
    parameter,
    points,
    positive,
)


@dataclasses.dataclass(frozen=True)
class Example(Checked):
    rate: float = parameter(10.0, 'how often', positive, 'Hz')
    samples: int = parameter(20, 'how many', number(1))
    share: float = parameter(0.5, 'a share', number(0.0, 1.0))
    mode: str = parameter('a', 'which', one_of('a', 'b'))
    enabled: bool = parameter(True, 'on or off')
    frame: str = parameter('map', 'a frame', frame_id)
    footprint: tuple = parameter(((0, 0), (1, 0), (0, 1)), 'an outline', points(3))
    limit: Optional[float] = parameter(None, 'unset: the model\'s', non_negative)

    def check_together(self):
        if self.samples > 100 and self.rate > 50:
            fail('samples', self.samples, 'must be <= 100 when ~rate > 50')


def test_values_are_typed_by_one_rule():
    config = Example(rate=5, samples=7.0, frame='/odom', footprint=[[0, 0], [1, 0], [0, 1]])
    assert config.rate == 5.0 and type(config.rate) is float
    assert config.samples == 7 and type(config.samples) is int  # 7.0 from a launch file is the 7 meant
    assert config.frame == 'odom'  # a leading "/" is dropped, as tf's listener drops it
    assert config.footprint == ((0, 0), (1, 0), (0, 1)) and config.limit is None


@pytest.mark.parametrize('name, value, problem', [
    ('rate', 0.0, 'must be > 0'), ('rate', math.nan, 'must be a finite number'), ('rate', True, 'must be a number'),
    ('rate', '10', 'must be a number'), ('samples', 2.5, 'must be a whole number'), ('samples', 0, 'must be >= 1'),
    ('share', 1.5, 'must be between 0 and 1'), ('mode', 'c', 'must be one of: a, b'),
    ('enabled', 1, 'must be true or false'), ('frame', '', 'must be a frame id'), ('frame', 'my map', 'frame id'),
    ('footprint', [[0, 0], [1, 0]], 'at least 3 [x, y] points'), ('limit', -1.0, 'must be >= 0')])
def test_a_bad_value_names_the_parameter_and_the_value(name, value, problem):
    with pytest.raises(ParameterError) as raised:
        Example(**{name: value})
    assert str(raised.value).startswith('parameter ~%s = %r: ' % (name, value)) and problem in str(raised.value)


def test_relations_between_fields_are_checked_after_the_fields():
    Example(samples=200, rate=10.0)
    with pytest.raises(ParameterError, match=r'~samples = 200: must be <= 100 when ~rate > 50'):
        Example(samples=200, rate=60)


def test_replace_checks_again():
    with pytest.raises(ParameterError, match='~share = 2.0'):
        Example().replace(share=2.0)
