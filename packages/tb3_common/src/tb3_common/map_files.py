"""map_server's map files, read and written as ros-planning/navigation's map_server (noetic) does. No ROS here.

A map is a YAML file of metadata and an image. Reading follows map_server's
main.cpp and image_loader.cpp: the keys `image` (relative to the YAML's
folder), `resolution`, `origin` [x, y, yaw], `negate`, `occupied_thresh` and
`free_thresh` are required, `mode` (trinary, scale, raw) is optional; each
pixel's channels are averaged, p = (255 - average) / 255 (after negate's
flip), p > occupied_thresh is 100, p < free_thresh is 0, else -1 (trinary)
or a linear 1..99 (scale); raw keeps the average as the cell's byte. The
image's top row is the map's highest y: cell row 0 is the image's last row.

Writing follows map_saver.cpp: a binary PGM, "P5" and a comment naming
map_saver.cpp and the resolution (%.3f), cells 0..threshold_free as 254,
>= threshold_occupied as 0, everything else (also -1) as 205; and a YAML
whose text is map_saver's printf, byte for byte: the image as `-f NAME` gave
it plus ".pgm", resolution and origin with %f, the yaw from the origin's
quaternion (tf2's getEulerYPR), and always `negate: 0`, `occupied_thresh:
0.65`, `free_thresh: 0.196` whatever --occ and --free were.

Images are read as SDL_image hands them to map_server: a greyscale or
palette image as one byte per pixel (a palette image's bytes are its
indices, not its colours), grey with alpha as RGBA, 16-bit grey as its high
byte. PGM files (P5, P2) are read here; every other format through PIL.
"""
import dataclasses
import math
import os
import re

import numpy as np
import yaml

from .grid import Grid
from .pose2d import quaternion_of_yaw, yaw_of_quaternion

TRINARY, SCALE, RAW = 'trinary', 'scale', 'raw'
MODES = (TRINARY, SCALE, RAW)
PGM_FREE, PGM_OCCUPIED, PGM_UNKNOWN = 254, 0, 205  # map_saver's pixel values
REQUIRED_KEYS = ('image', 'resolution', 'origin', 'negate', 'occupied_thresh', 'free_thresh')


class MapFileError(ValueError):
    """A map file that cannot be read or written; the message names the file and the key."""

    def __init__(self, path, key, problem):
        self.path, self.key, self.problem = path, key, problem
        where = '%s: key %r' % (path, key) if key else path
        super(MapFileError, self).__init__('%s: %s' % (where, problem))


@dataclasses.dataclass(frozen=True)
class MapMetadata(object):
    """A map YAML's keys, checked; `image` is the image's path (resolved against the YAML's folder)."""
    image: str
    resolution: float
    origin: tuple = (0.0, 0.0, 0.0)
    negate: int = 0
    occupied_thresh: float = 0.65
    free_thresh: float = 0.196
    mode: str = TRINARY


@dataclasses.dataclass(frozen=True)
class LoadedMap(object):
    """A map as map_server serves it: the grid's geometry, int8 values [iy, ix] (row 0 = lowest y)."""
    grid: Grid
    values: np.ndarray
    metadata: MapMetadata


@dataclasses.dataclass(frozen=True)
class SaverConfig(object):
    """map_saver's options (--occ, --free, -f) under its own variables' names, checked as it checks them."""
    threshold_occupied: int = 65
    threshold_free: int = 25
    mapname: str = 'map'

    def __post_init__(self):
        if not 1 <= self.threshold_occupied <= 100:
            raise ValueError('threshold_occupied must be between 1 and 100')
        if not 0 <= self.threshold_free <= 100:
            raise ValueError('threshold_free must be between 0 and 100')
        if self.threshold_occupied <= self.threshold_free:
            raise ValueError('threshold_free must be smaller than threshold_occupied')
        if not self.mapname:
            raise ValueError('the map name (-f) must not be empty')


# --- reading -------------------------------------------------------------------
def _number(path, document, key):
    value = document[key]
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise MapFileError(path, key, 'must be a finite number, not %r' % (value,))
    return float(value)


def read_metadata(path):
    """The MapMetadata of a map YAML, or MapFileError naming the file and the key."""
    try:
        with open(path) as stream:
            document = yaml.safe_load(stream)
    except OSError as error:
        raise MapFileError(path, None, 'cannot open the map file: %s' % (error.strerror or error))
    except yaml.YAMLError as error:
        raise MapFileError(path, None, 'not valid YAML: %s' % ' '.join(str(error).split()))
    if not isinstance(document, dict):
        raise MapFileError(path, None, 'a map file is a mapping of the keys %s, not %r'
                           % (', '.join(REQUIRED_KEYS), document))
    for key in REQUIRED_KEYS:
        if key not in document:
            raise MapFileError(path, key, 'missing: a map file needs %s' % ', '.join(REQUIRED_KEYS))
    resolution = _number(path, document, 'resolution')
    if resolution <= 0:
        raise MapFileError(path, 'resolution', 'must be > 0 (metres per pixel), not %r' % document['resolution'])
    negate = document['negate']
    if isinstance(negate, bool) or not isinstance(negate, int):
        raise MapFileError(path, 'negate', 'must be an integer (0 or 1), not %r' % (negate,))
    origin = document['origin']
    if (not isinstance(origin, list) or len(origin) != 3 or any(
            isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value)
            for value in origin)):
        raise MapFileError(path, 'origin', 'must be [x, y, yaw], three finite numbers, not %r' % (origin,))
    mode = document.get('mode', TRINARY)
    if mode not in MODES:
        raise MapFileError(path, 'mode', 'must be one of %s, not %r' % (', '.join(MODES), mode))
    image = document['image']
    if not isinstance(image, str) or not image:
        raise MapFileError(path, 'image', 'must be the name of an image file, not %r' % (image,))
    return MapMetadata(os.path.join(os.path.dirname(path), image), resolution, tuple(float(v) for v in origin),
                       negate, _number(path, document, 'occupied_thresh'),
                       _number(path, document, 'free_thresh'), mode)


def _read_pgm(stream):
    """Pixels (h, w) uint8 of a P5 or P2 PGM, scaled to 0..255 as SDL_image scales a smaller maxval."""
    data = stream.read()
    fields, position = [], 0
    token = re.compile(rb'(?:\s|#[^\n]*\n?)*([^\s#]+)')
    for _ in range(4):
        match = token.match(data, position)
        if not match:
            raise ValueError('a truncated PGM header')
        fields.append(match.group(1))
        position = match.end()
    kind, width, height, maxval = fields[0], int(fields[1]), int(fields[2]), int(fields[3])
    if not 0 < maxval <= 255 or width < 1 or height < 1:
        raise ValueError('an unsupported PGM (%d x %d, maxval %d)' % (width, height, maxval))
    if kind == b'P5':
        pixels = np.frombuffer(data, dtype=np.uint8, count=width * height, offset=position + 1)
    else:
        pixels = np.array(data[position:].split()[:width * height], dtype=np.int64)
        if pixels.size < width * height:
            raise ValueError('fewer pixels than %d x %d' % (width, height))
    pixels = pixels.reshape(height, width).astype(np.int64)
    return (pixels * 255 // maxval).astype(np.uint8) if maxval < 255 else pixels.astype(np.uint8)


def read_image(path):
    """(pixels (h, w, channels) uint8, has_alpha) of an image, as SDL_image gives them to map_server."""
    with open(path, 'rb') as stream:
        if stream.read(2) in (b'P5', b'P2'):
            stream.seek(0)
            return _read_pgm(stream)[:, :, None], False
    from PIL import Image  # Debian's python3-pil, for every other format
    with Image.open(path) as image:
        image.load()
        mode = image.mode
        if mode in ('L', 'P'):
            pixels = np.asarray(image)  # a palette image: its indices, as SDL's 8-bit surface
        elif mode.startswith('I'):  # 16-bit grey: libpng strips it to its high byte for SDL
            pixels = (np.asarray(image).astype(np.int64) >> 8).clip(0, 255).astype(np.uint8)
        elif mode == '1':
            pixels = np.asarray(image.convert('L'))
        elif mode in ('RGBA', 'LA', 'PA'):
            return np.asarray(image.convert('RGBA')), True
        else:
            return np.asarray(image.convert('RGB')), False
    return pixels[:, :, None], False


def occupancy(pixels, has_alpha, negate=0, occupied_thresh=0.65, free_thresh=0.196, mode=TRINARY):
    """int8 cell values [iy, ix] (row 0 = the image's last row) of pixels (h, w, channels), as image_loader.cpp."""
    channels = pixels.shape[2]
    averaged = channels if mode == TRINARY or not has_alpha else channels - 1  # trinary averages alpha in too
    average = pixels[:, :, :averaged].astype(np.float64).sum(axis=2) / averaged
    # map_server reads "alpha" from the last byte of any pixel of more than one (for RGB: blue).
    alpha = pixels[:, :, -1] if channels > 1 else np.ones(pixels.shape[:2])
    if negate:
        average = 255.0 - average
    if mode == RAW:  # the average's byte, as int8: 255 reads -1
        values = average.astype(np.uint8).view(np.int8)
    else:
        occ = (255.0 - average) / 255.0
        with np.errstate(invalid='ignore', divide='ignore'):
            scaled = np.nan_to_num(1.0 + 98.0 * (occ - free_thresh) / (occupied_thresh - free_thresh))
        between = -1 if mode == TRINARY else np.where(alpha < 1.0, -1, scaled.astype(np.int64))
        values = np.where(occ > occupied_thresh, 100, np.where(occ < free_thresh, 0, between)).astype(np.int8)
    return np.ascontiguousarray(values[::-1])


def load_image(metadata, where=None):
    """The LoadedMap of `metadata`'s image; MapFileError names `where` (the YAML) and 'image'."""
    where = where or metadata.image
    if not os.path.isfile(metadata.image):
        raise MapFileError(where, 'image', 'image file %s does not exist' % metadata.image)
    try:
        pixels, has_alpha = read_image(metadata.image)
    except (OSError, ValueError, SyntaxError) as error:
        raise MapFileError(where, 'image', 'cannot read image file %s: %s' % (metadata.image, error))
    values = occupancy(pixels, has_alpha, metadata.negate, metadata.occupied_thresh, metadata.free_thresh,
                       metadata.mode)
    grid = Grid(metadata.resolution, values.shape[1], values.shape[0], metadata.origin)
    return LoadedMap(grid, values, metadata)


def load_map(path):
    """The LoadedMap of a map YAML, or MapFileError naming the file and the key."""
    return load_image(read_metadata(path), path)


# --- writing -------------------------------------------------------------------
def pgm_bytes(values, resolution, threshold_occupied=65, threshold_free=25):
    """map_saver's PGM of int8 `values` [iy, ix]: header and pixels, the highest row first."""
    values = np.asarray(values).astype(np.int16)
    height, width = values.shape
    pixels = np.full(values.shape, PGM_UNKNOWN, dtype=np.uint8)
    pixels[values >= threshold_occupied] = PGM_OCCUPIED
    pixels[(values >= 0) & (values <= threshold_free)] = PGM_FREE  # map_saver tests this one first
    # The message's float32 resolution, printed as C's printf promotes it.
    header = 'P5\n# CREATOR: map_saver.cpp %.3f m/pix\n%d %d\n255\n' % (float(np.float32(resolution)), width, height)
    return header.encode('ascii') + pixels[::-1].tobytes()


def yaml_text(image, resolution, origin_xy, orientation):
    """map_saver's YAML: `image` as written, `orientation` the origin's quaternion (x, y, z, w)."""
    return ('image: %s\nresolution: %f\norigin: [%f, %f, %f]\nnegate: 0\noccupied_thresh: 0.65\n'
            'free_thresh: 0.196\n\n' % (image, float(np.float32(resolution)), origin_xy[0], origin_xy[1],
                                         yaw_of_quaternion(*orientation)))


def save_map(grid, values, config=SaverConfig(), orientation=None, image=None):
    """Writes config.mapname + '.pgm' and '.yaml' as map_saver does; returns both paths.

    `orientation`: the origin's quaternion as the message carried it (default:
    the grid's yaw); `image`: the name the YAML gives the image (map_saver's is
    the PGM's path as -f gave it; a map meant to move with its folder wants its
    bare file name). MapFileError names the file that cannot be written."""
    pgm, yaml_path = config.mapname + '.pgm', config.mapname + '.yaml'
    orientation = quaternion_of_yaw(grid.origin[2]) if orientation is None else orientation
    for path, content in ((pgm, pgm_bytes(values, grid.resolution, config.threshold_occupied,
                                          config.threshold_free)),
                          (yaml_path, yaml_text(pgm if image is None else image, grid.resolution,
                                                grid.origin[:2], orientation).encode('utf-8'))):
        try:
            with open(path, 'wb') as stream:
                stream.write(content)
        except OSError as error:
            raise MapFileError(path, None, "couldn't save map file: %s" % (error.strerror or error))
    return pgm, yaml_path
