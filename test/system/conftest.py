"""Fixtures of the system tests (see tb3_system_utils.py for what they are)."""
import pytest

from tb3_system_utils import Processes, harness, master_uri


@pytest.fixture
def ros_port(monkeypatch):
    """A free loopback port, and this process's (so its children's) ROS environment set to it."""
    port = harness.free_port()
    monkeypatch.setenv('ROS_MASTER_URI', master_uri(port))
    monkeypatch.setenv('ROS_HOSTNAME', 'localhost')
    monkeypatch.delenv('ROS_IP', raising=False)
    return port


@pytest.fixture
def processes(tmp_path):
    started = Processes(tmp_path)
    try:
        yield started
    finally:
        started.stop_all()
