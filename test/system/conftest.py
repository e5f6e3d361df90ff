"""Fixtures of the system tests (see tb3_system_utils.py for what they are)."""
import os

import pytest

from tb3_harness.screen import screen_env, start_xvfb

from tb3_system_utils import MASTER_TIMEOUT, Processes, harness, master_uri, registered, wait_until

# teleop_pty is both imported by the teleop's test files and their plugin (its fixtures): its asserts are
# rewritten only if pytest knows it before they import it.
pytest.register_assert_rewrite('teleop_pty')


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


@pytest.fixture
def screen(processes, monkeypatch):
    """A screen of the test's own (Xvfb), with this process's (so its children's) DISPLAY set to it, as
    on a desktop where the launches open rviz: its display."""
    xvfb, display = start_xvfb()
    processes.add(xvfb, server=True)
    for name, value in screen_env(display).items():
        monkeypatch.setenv(name, value)
    return display


@pytest.fixture(scope='module')
def module_master(tmp_path_factory):
    """One roscore for a module's tests, on a free loopback port, with this
    process's ROS environment pointed at it: a roscore costs 2-3 wall s to
    start and 1 to stop (measured), which tests that only need a master pay
    once this way. See `shared_master`."""
    port = harness.free_port()
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv('ROS_MASTER_URI', master_uri(port))
        patch.setenv('ROS_HOSTNAME', 'localhost')
        patch.delenv('ROS_IP', raising=False)
        started = Processes(tmp_path_factory.mktemp('module_master'))
        try:
            started.start_master('roscore', port)
            import rosgraph
            server = rosgraph.Master('/tb3_test')
            # roscore sets its parameters and starts rosout after its master answers.
            assert wait_until(lambda: server.hasParam('/run_id') and registered(server, '/rosout'), MASTER_TIMEOUT), \
                'roscore -p %d: no /run_id or /rosout within %.0f s' % (port, MASTER_TIMEOUT)
            yield port, set(server.getParamNames())
        finally:
            started.stop_all()


@pytest.fixture
def shared_master(module_master):
    """The module's roscore, as a fresh one would be to a test that starts its
    own nodes: the parameters it started with, and only those, at the start of
    each test (a launch sets its parameters, and a test may set more; a node
    never sees those of an earlier test), and no node but rosout registered. Its port.

    An earlier test's node that died without unregistering stays in the master
    under its old address. When a node of the same name registers, the master
    tells that address to shut down, and if the port has since been reused by
    another process (in CI, once: a `rostopic echo`), that one obeys. So the
    leftovers are unregistered first, as `rosnode cleanup` does."""
    import contextlib
    import io

    import rosgraph
    import rosnode
    port, baseline = module_master
    assert os.environ['ROS_MASTER_URI'] == master_uri(port)
    server = rosgraph.Master('/tb3_test')
    for name in sorted(set(server.getParamNames()) - baseline):
        if server.hasParam(name):   # gone with a namespace deleted before it
            server.deleteParam(name)
    leftovers = set(rosnode.get_node_names()) - {'/rosout'}
    with contextlib.redirect_stdout(io.StringIO()):  # it prints a line per node
        rosnode.cleanup_master_blacklist(server, sorted(leftovers))
    assert set(rosnode.get_node_names()) == {'/rosout'}, rosnode.get_node_names()
    return port
