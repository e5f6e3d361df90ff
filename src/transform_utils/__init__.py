"""The tutorial's scripts say `from transform_utils import ...`: this top-level
module serves them the rbx1_nav helpers."""
from rbx1_nav.transform_utils import normalize_angle, quat_to_angle  # noqa: F401
