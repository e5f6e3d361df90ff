"""What other threads hand the step loop, and the world drawn for rviz.

pybullet is not to be called from two threads, and a spawned robot's
topics join the step loop's publishing: every change to the world runs in
the step loop, between steps (Requests.run).
"""
import queue
import threading
import time

from visualization_msgs.msg import MarkerArray

from ..simulation import ModelStateError
from . import messages

REQUEST_TIMEOUT = 10.0  # wall s a service waits for the step loop to take its request
REQUEST_POLL = 0.1      # wall s between looks at the node's end while waiting


class Requests(object):
    """Work of other threads (services, dynamic_reconfigure), for the step loop."""

    def __init__(self, life):
        self.life = life
        self._queue = queue.Queue()
        self.callers = set()  # the nodes that asked for something: lockstep serves them before each step

    def run(self, work, timeout=REQUEST_TIMEOUT, message=None):
        """work()'s result, run by the step loop between steps; its exception raised here. `message`:
        the request or message that asked for it, whose caller lockstep then knows."""
        caller = getattr(message, '_connection_header', {}).get('callerid')
        if caller:
            self.callers.add(caller)
        done, result = threading.Event(), {}
        self._queue.put((work, done, result))
        deadline = time.monotonic() + timeout
        while not done.wait(REQUEST_POLL):
            if self.life.stopping:
                raise ModelStateError('the simulator is shutting down')
            if time.monotonic() > deadline:
                raise ModelStateError('the simulator did not get to the request within %g s (wall)' % timeout)
        if 'error' in result:
            raise result['error']
        return result.get('value')

    def serve(self):
        """Run what waits (in the step loop); how many there were."""
        served = 0
        while True:
            try:
                work, done, result = self._queue.get_nowait()
            except queue.Empty:
                return served
            served += 1
            try:
                result['value'] = work()
            except Exception as error:  # handed back to the thread that asked
                result['error'] = error
            done.set()


class Markers(object):
    """The world's obstacles and objects on world_markers (latched), in the world
    frame (or odom's when there is none)."""

    def __init__(self, sim, publishers, frame):
        self.sim = sim
        self.frame = frame
        self.publisher = publishers.advertise('world_markers', MarkerArray, latch=True)
        self.changed()

    def changed(self, stamp=None):
        """Draw the world anew (in the step loop)."""
        self.publisher.publish(messages.world_markers(self.frame, self.sim.world.visual_shapes(),
                                                      stamp or messages.stamp_of(self.sim.now_ns)))

    def moving(self):
        return any(not body.static for body in self.sim.world.objects.values())
