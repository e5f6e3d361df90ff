"""`rosrun image_view image_view image:=/camera/rgb/image_raw` (Debian's image_view)
shows the Waffle Pi's camera: on a screen of the test's own (Xvfb), its window
shows the pillars of turtlebot3_world that the robot faces at its spawn pose
(their green, which nothing else on the screen is)."""
import os

from tb3_harness.screen import green_pixels, save_png, screen_env, screenshot, start_xvfb

from tb3_system_utils import wait_until

MIN_GREEN = 1000  # pillar pixels in the window (a 640 x 480 image shows tens of thousands)


def test_image_view_shows_the_waffle_pis_camera(ros_port, processes, tmp_path):
    processes.start_master('roscore', ros_port)
    sim = processes.start('sim', ['roslaunch', '--wait', 'tb3_sim_bringup', 'tb3_world.launch', 'model:=waffle_pi'])
    xvfb, display = start_xvfb()
    processes.add(xvfb, server=True)
    viewer = processes.start('image_view', ['rosrun', 'image_view', 'image_view', 'image:=/camera/rgb/image_raw'],
                             env=dict(os.environ, **screen_env(display)))
    shots = []

    def shown():
        assert sim.running(), sim.describe()
        assert viewer.running(), viewer.describe()
        shots[:] = [screenshot(display)]
        return green_pixels(shots[0]) >= MIN_GREEN
    ok = wait_until(shown, 90.0, poll=1.0)
    save_png(shots[0], str(tmp_path / 'image_view.png'))
    print('MEASURED image_view: %d green pixels on the screen (%s)' % (green_pixels(shots[0]), tmp_path))
    assert ok, 'image_view shows no image of the pillars; see %s; its output:\n%s' % (tmp_path, viewer.output())
