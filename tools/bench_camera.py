"""The cameras' figures for `make bench` (tools/bench.py): what a frame costs
to render, by size, and whether the world keeps real time with a camera read
(by a reader, or shown in rviz on a screen of its own).
"""
import os
import time

from bench_sim import LAUNCH, ROOT, WALLED_WORLD, median, verdict

from tb3_harness.measure import cpu_seconds, sim_pid, sim_uri
from tb3_harness.processes import Process, say, wait_until
from tb3_harness.screen import start_xvfb
from tb3_harness.tcpros_reader import TcprosReader

FRAME_SIZES = [(320, 240), (640, 360), (640, 480), (1280, 720), (1920, 1080)]
# (label, model, camera size and rate or None for the defaults, camera topics
# read; None: rviz shows camera.rviz on a screen of its own)
ALL_OF_THE_R200 = ['rgb/image_raw', 'depth/image_raw', 'depth/points']
CAMERA_ROWS = [('waffle_pi, defaults', 'waffle_pi', None, None, ['rgb/image_raw']),
               ('waffle_pi, 640 x 480 at 30 Hz (Gazebo\'s)', 'waffle_pi', (640, 480), 30.0, ['rgb/image_raw']),
               ('waffle_pi, defaults, rviz showing camera.rviz', 'waffle_pi', None, None, None),
               ('waffle_pi, 640 x 480 at 30 Hz, rviz showing camera.rviz', 'waffle_pi', (640, 480), 30.0, None),
               ('waffle, defaults, colour, depth and cloud', 'waffle', None, None, ALL_OF_THE_R200),
               ('waffle, 640 x 360 at 30 Hz, colour, depth and cloud', 'waffle', (640, 360), 30.0, ALL_OF_THE_R200),
               ('waffle, 1920 x 1080 at 30 Hz (Gazebo\'s), all three', 'waffle', (1920, 1080), 30.0, ALL_OF_THE_R200)]
RVIZ_SETTLE = 15.0    # wall s for rviz to start and show the camera before measuring


def measure_frames(runs):
    """Median wall and CPU ms to render one frame (colour and depth) of the
    Waffle's camera in turtlebot3_world, by size, with pybullet's EGL plugin
    on Mesa's llvmpipe (the simulator's choice) and, in a world without it,
    with its TinyRenderer (once loaded, the plugin renders every image)."""
    from tb3_sim_nav.camera import Camera
    from tb3_sim_nav.frames import planar
    from tb3_sim_nav.params import resolve
    from tb3_sim_nav.robot_model import load_model
    from tb3_sim_nav.simulation import Simulation
    from tb3_sim_nav.world_file import load_world
    model = load_model(os.path.join(ROOT, 'urdf', 'turtlebot3_waffle.urdf'))
    obstacles = load_world('turtlebot3_world', os.path.join(ROOT, 'worlds')).obstacles
    costs, egl = {}, None
    for name, cameras in (('egl', True), ('tiny', False)):
        simulation = Simulation(resolve(lambda key, default: default), obstacles, cameras=cameras)
        try:
            if cameras:
                import pybullet
                egl = simulation.world.renderer != pybullet.ER_TINY_RENDERER
            body = simulation.add_robot('', model, planar(-2.0, -0.5)).body
            for width, height in FRAME_SIZES:
                camera = Camera(body, model.cameras[0], width, height, model.cameras[0].horizontal_fov, 30.0)
                camera.render()  # the first frame sets the renderer up
                walls, cpus = [], []
                for _ in range(runs * 3):
                    wall, cpu = time.perf_counter(), time.process_time()
                    camera.render()
                    walls.append(1000.0 * (time.perf_counter() - wall))
                    cpus.append(1000.0 * (time.process_time() - cpu))
                costs[(name, width, height)] = (median(walls), median(cpus))
                say('frame %d x %d, %s: %.1f ms wall, %.1f ms CPU'
                    % ((width, height, name) + costs[(name, width, height)]))
        finally:
            simulation.close()
    return costs, egl


def measure_camera(log_dir, model, size, rate, topics, seconds):
    """At factor 1 in turtlebot3_world, with the camera's `topics` read (None:
    rviz shows camera.rviz on an Xvfb screen): sim seconds per wall second, the
    simulator's CPU (% of a core) and the colour images a sim second (a camera
    drops frames rather than hold the world back: ros/sensor_io.py)."""
    import rosgraph
    master = rosgraph.Master('/tb3_bench')
    for key, value in zip(('camera_width', 'camera_height', 'camera_rate'), (size or (None, None)) + (rate,)):
        if value is None:
            if master.hasParam('/tb3_sim/' + key):
                master.deleteParam('/tb3_sim/' + key)
        else:
            master.setParam('/tb3_sim/' + key, value)
    for key in ('scan', 'imu'):
        master.setParam('/tb3_sim/' + key, True)
    sim = Process('camera_' + model, LAUNCH + [WALLED_WORLD, 'model:=' + model], log_dir)
    readers, viewers = [], []
    try:
        frames = []  # one None a colour image (counted, not kept; beside rviz, by one more reader)
        readers = [TcprosReader(sim_uri, '/camera/rgb/image_raw', keep=lambda body: frames.append(None))] + [
            TcprosReader(sim_uri, topic) for topic in ['/clock'] + ['/camera/' + topic for topic in topics or []
                                                                     if topic != 'rgb/image_raw']]
        clock = readers[1]
        wait_until(lambda: clock.clock is not None and clock.clock > 2.0, 120, '/clock')
        if topics is None:
            xvfb, display = start_xvfb()
            view = os.path.join(ROOT, 'rviz', 'camera.rviz')
            viewers = [xvfb, Process('rviz', ['rosrun', 'rviz', 'rviz', '-d', view], log_dir,
                                     env=dict(os.environ, DISPLAY=display))]
            time.sleep(RVIZ_SETTLE)
        pid = sim_pid()
        sim_start, wall_start, cpu_start, frames_start = clock.clock, time.monotonic(), cpu_seconds(pid), len(frames)
        time.sleep(seconds)
        sim_end, wall_end, cpu_end, frames_end = clock.clock, time.monotonic(), cpu_seconds(pid), len(frames)
        wall = wall_end - wall_start
        return ((sim_end - sim_start) / wall, 100.0 * (cpu_end - cpu_start) / wall,
                (frames_end - frames_start) / (sim_end - sim_start))
    finally:
        for process in reversed(viewers):
            process.stop()
        for reader in readers:
            reader.close()
        sim.stop()
        for key in ('camera_width', 'camera_height', 'camera_rate'):
            if master.hasParam('/tb3_sim/' + key):
                master.deleteParam('/tb3_sim/' + key)


def measure(log_dir, runs, seconds):
    """Frame costs and every row of CAMERA_ROWS, `runs` times each: (frames, egl, {label: [results]})."""
    frames, egl = measure_frames(runs)
    cameras = {}
    for label, model, size, rate, topics in CAMERA_ROWS:
        cameras[label] = [measure_camera(log_dir, model, size, rate, topics, seconds) for _ in range(runs)]
        say('camera %s: real-time factor %s, CPU %s, frames a sim second %s' % (
            label, [round(r, 2) for r, _, _ in cameras[label]], [round(c, 1) for _, c, _ in cameras[label]],
            [round(f, 1) for _, _, f in cameras[label]]))
    return frames, egl, cameras


def table(frames, egl, cameras):
    """The camera's lines of the bench's table."""
    lines = ['one frame of the Waffle\'s camera (colour and depth), wall / CPU ms, %s; TinyRenderer:'
             % ('EGL on llvmpipe' if egl else 'EGL not loaded: TinyRenderer')]
    for width, height in FRAME_SIZES:
        lines.append('%-58s %6.1f / %5.1f ms;  %6.1f / %5.1f ms' % (
            ('  %d x %d' % (width, height),) + frames[('egl', width, height)] + frames[('tiny', width, height)]))
    lines.append('factor 1 in turtlebot3_world, the camera read: real-time factor, CPU of the simulator, '
                 'colour images a sim second:')
    for label, _, _, _, _ in CAMERA_ROWS:
        factor = median([r for r, _, _ in cameras[label]])
        lines.append('%-58s %7.2f  %5.1f%%  %5.1f Hz  %s' % (
            '  ' + label, factor, median([c for _, c, _ in cameras[label]]),
            median([f for _, _, f in cameras[label]]), 'real time: %s' % verdict(factor >= 0.95)))
    return lines
