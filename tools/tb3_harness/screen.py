"""A screen of a test's own: Xvfb on a display it picks itself, and screenshots as numpy arrays.

Screenshots come from imagemagick's `import -window root -depth 8 ppm:-`,
decoded here, so no imaging library is needed.
"""
import re
import subprocess
import time

import numpy

from .processes import Process

SIZE = (1280, 800)
#: How programs draw on a test's screen (screen_env passes it to what a test starts there).
#: Mesa's llvmpipe (bookworm: Mesa 22.3, LLVM 15) crashed rviz at random in its first
#: frame, inside LLVM as it compiled a shader (SIGSEGV in llvm::FixedVectorType::get; a few starts
#: in a hundred on a busy machine; llvm-project#57850 has it in GNOME); softpipe compiles nothing
#: with LLVM, and the tests see the same views in it (doc/testing.md has the runs).
RENDERING = {'GALLIUM_DRIVER': 'softpipe'}


def start_xvfb(size=SIZE, timeout=20.0, **options):
    """Xvfb on a display it picks (-displayfd 1 prints the number): (Process, ':N').
    `options` go to Process (die_with_parent...)."""
    xvfb = Process('xvfb', ['Xvfb', '-displayfd', '1', '-screen', '0', '%dx%dx24' % size, '-nolisten', 'tcp'],
                   **options)
    deadline = time.monotonic() + timeout
    while True:
        number = re.search(r'^(\d+)$', xvfb.output(), re.M)
        if number and xvfb.running():
            return xvfb, ':' + number.group(1)
        if not xvfb.running() or time.monotonic() > deadline:
            description = xvfb.describe()
            xvfb.stop()
            raise RuntimeError('Xvfb did not start: %s' % description)
        time.sleep(0.05)


def screen_env(display):
    """The variables a program started on `display` needs: DISPLAY and RENDERING. Given to each
    program (or set for one test by monkeypatch), never to this process for good: a simulator
    started later would render its cameras with softpipe too."""
    return dict(RENDERING, DISPLAY=display)


def read_ppm(data):
    """A binary PPM (P6, maxval 255) as an H x W x 3 int array."""
    fields, position = [], 0
    while len(fields) < 4:
        match = re.compile(rb'\s*(#[^\n]*\n\s*)*(\S+)').match(data, position)
        fields.append(match.group(2))
        position = match.end()
    if fields[0] != b'P6' or int(fields[3]) != 255:
        raise ValueError('not an 8-bit binary PPM: %r' % fields)
    width, height = int(fields[1]), int(fields[2])
    pixels = numpy.frombuffer(data, numpy.uint8, width * height * 3, position + 1)
    return pixels.reshape(height, width, 3).astype(int)


def screenshot(display):
    data = subprocess.run(['import', '-display', display, '-window', 'root', '-depth', '8', 'ppm:-'],
                          stdout=subprocess.PIPE, stderr=subprocess.PIPE, timeout=30, check=True).stdout
    return read_ppm(data)


def save_png(image, path):
    subprocess.run(['convert', 'ppm:-', path], input=b'P6 %d %d 255\n' % image.shape[1::-1]
                   + image.astype(numpy.uint8).tobytes(), check=True, timeout=30)


def green_pixels(image):
    """Pixels of the worlds' pillar green (0.3, 0.55, 0.3), lit or shaded."""
    r, g, b = image[..., 0], image[..., 1], image[..., 2]
    return int(((g > 60) & (g > 1.4 * r) & (g > 1.4 * b)).sum())
