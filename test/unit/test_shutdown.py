"""A signal that lands while the step loop writes a message ends the node; it cannot deadlock (issue 18).

Python runs a signal handler in the main thread between two bytecodes. The
fake socket here sends SIGINT to its own process from inside send(), so the
handler runs exactly while NonBlockingConnection.write_data holds the
connection's lock: the moment that hung the simulator when rospy's handler
closed the connections itself. Each case runs in a process of its own, so a
deadlock costs the test a time-out, not the test run.
"""
import subprocess
import sys
import textwrap

SCENARIO = textwrap.dedent('''
    import os, signal, sys
    from tb3_sim_nav.ros.transport import Backlogs, NonBlockingConnection
    from tb3_common.ros.lifecycle import Life

    class SignallingSocket(object):
        """Sends SIGINT to this process from inside its first send()."""
        sent = 0
        def setblocking(self, flag):
            pass
        def send(self, data):
            if not self.sent:
                os.kill(os.getpid(), signal.SIGINT)
            self.sent += 1
            return len(data)

    class Connection(object):
        socket, endpoint_id, stat_bytes, stat_num_msg = SignallingSocket(), 'reader', 0, 0
        def close(self):
            self.socket = None

    connection = NonBlockingConnection(Connection(), '/scan', Backlogs(), on_drop=lambda c: None)
    life = Life()
    if sys.argv[1] == 'lifecycle':
        life.handle_signals()  # the signal only sets the flag
    else:  # as rospy's handler did: the shutdown's work inside the handler
        signal.signal(signal.SIGINT, lambda number, frame: connection.close())
    written = 0
    while not life.stopping and written < 1000:  # the step loop
        connection.write_data(b'x' * 100)
        written += 1
    connection.close()  # as life.finish() has rospy do, after the loop
    print('finished after %d writes: %s' % (written, life.reason))
''')


def run(handler, timeout):
    return subprocess.run([sys.executable, '-c', SCENARIO, handler], stdout=subprocess.PIPE,
                          stderr=subprocess.STDOUT, universal_newlines=True, timeout=timeout)


def test_a_signal_inside_write_data_only_sets_the_flag_and_the_loop_finishes():
    done = run('lifecycle', timeout=30)
    assert done.returncode == 0, done.stdout
    assert 'finished after 1 writes: SIGINT received' in done.stdout, done.stdout


def test_the_same_moment_deadlocks_a_handler_that_closes_the_connection():
    """The scenario does reach the lock: the old way (work in the handler) never finishes."""
    try:
        hung = run('close-in-handler', timeout=5)
    except subprocess.TimeoutExpired:
        return
    raise AssertionError('the handler that closes the connection did not deadlock: %s' % hung.stdout)


HANGS_ON_ITS_WAY_OUT = textwrap.dedent('''
    import os, signal, threading, time
    from tb3_common.ros import lifecycle
    lifecycle.STACKS_AFTER = 0.5
    life = lifecycle.Life()
    life.handle_signals()
    def stuck_in_a_join():
        threading.Event().wait(3.0)   # a thread the interpreter would wait for at exit
    os.kill(os.getpid(), signal.SIGINT)
    stuck_in_a_join()
    print('ended: %s' % life.reason, flush=True)
''')


def test_a_node_still_running_after_its_end_was_asked_for_prints_where_its_threads_are():
    """Once an end is asked for, a node that has not ended STACKS_AFTER s later prints every thread's stack."""
    done = subprocess.run([sys.executable, '-c', HANGS_ON_ITS_WAY_OUT], stdout=subprocess.PIPE,
                          stderr=subprocess.STDOUT, universal_newlines=True, timeout=30)
    assert done.returncode == 0, done.stdout
    assert 'Timeout (0:00:00.500000)!' in done.stdout, done.stdout
    assert 'in stuck_in_a_join' in done.stdout, done.stdout
    assert done.stdout.rstrip().endswith('ended: SIGINT received'), done.stdout


def test_a_callback_does_not_run_once_an_end_was_asked_for_and_a_publish_to_a_closed_topic_ends_it_quietly():
    import faulthandler

    import rospy

    from tb3_common.ros.lifecycle import Life
    life, calls = Life(), []

    def publishes(message):  # as amcl's scan callback when rospy closes its topics under it
        calls.append(message)
        if message == 'scan 2':
            life.request_stop('SIGINT received')
            faulthandler.cancel_dump_traceback_later()  # the stacks' print request_stop arms: not here
        raise rospy.ROSException('publish() to a closed topic')
    callback = life.callback(publishes)
    try:
        callback('scan 1')  # the node is not ending: the error is the callback's own, for rospy to log
        raise AssertionError('a running node\'s callback error was swallowed')
    except rospy.ROSException:
        pass
    assert callback('scan 2') is None  # the end came while it ran: quiet
    assert callback('scan 3') is None and calls == ['scan 1', 'scan 2']  # once ending, it does not run
