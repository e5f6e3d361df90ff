"""How map_server's loader reads a map's files (tb3_common.map_files.load_map): image_loader.cpp's rules
(the trinary thresholds and negate, scale and raw modes, colour and alpha, palette images, ASCII PGM and
small maxvals, the origin and relative and absolute image paths, the default mode), and every error of
a map's YAML or image in one line naming the file and the key."""
import numpy as np
import pytest
from PIL import Image

from tb3_common import map_files
from tb3_common.grid import Grid
from tb3_common.map_files import MapFileError


def _write_yaml(path, **keys):
    text = ''.join('%s: %s\n' % (key, value) for key, value in keys.items() if value is not None)
    path.write_text(text)
    return path


def _map_yaml(folder, image='m.png', **changes):
    keys = dict(image=image, resolution=0.05, origin='[1.0, -2.0, 0.0]', negate=0, occupied_thresh=0.65,
                free_thresh=0.196)
    keys.update(changes)
    return _write_yaml(folder / 'm.yaml', **keys)


# --- image_loader.cpp's rules ------------------------------------------------------------
def _load_pixels(tmp_path, pixels, image_mode, **keys):
    Image.fromarray(np.asarray(pixels, dtype=np.uint8), image_mode).save(str(tmp_path / 'm.png'))
    return map_files.load_map(str(_map_yaml(tmp_path, **keys))).values[::-1]  # back to image rows


def test_trinary_thresholds_and_negate(tmp_path):
    # p = (255 - v) / 255: 89 -> 0.651 (> 0.65), 90 -> 0.647, 205 -> 0.19608 (not < 0.196), 206 -> 0.192.
    grey = [[0, 89, 90, 205, 206, 254, 255]]
    assert _load_pixels(tmp_path, grey, 'L').tolist() == [[100, 100, -1, -1, 0, 0, 0]]
    # negate: p = v / 255: 89 -> 0.349 and 90 -> 0.353 between the thresholds, 205 -> 0.804 occupied.
    assert _load_pixels(tmp_path, grey, 'L', negate=1).tolist() == [[0, -1, -1, 100, 100, 100, 100]]


def test_scale_mode_maps_between_the_thresholds_linearly(tmp_path):
    # 128: p = 127/255 = 0.49804; 1 + 98 * (0.49804 - 0.196) / (0.65 - 0.196) = 66.2 -> 66 (truncated).
    values = _load_pixels(tmp_path, [[0, 128, 205, 254]], 'L', mode='scale')
    assert values.tolist() == [[100, 66, 1, 0]]


def test_raw_mode_keeps_the_byte(tmp_path):
    assert _load_pixels(tmp_path, [[0, 37, 100, 200, 255]], 'L', mode='raw').tolist() == [[0, 37, 100, -56, -1]]
    assert _load_pixels(tmp_path, [[0, 200]], 'L', mode='raw', negate=1).tolist() == [[-1, 55]]


def test_colour_is_averaged_and_trinary_averages_alpha_in(tmp_path):
    # RGB (0, 0, 255): mean 85 -> p 0.667: occupied; (255, 255, 0): mean 170 -> p 0.333: unknown.
    assert _load_pixels(tmp_path, [[[0, 0, 255], [255, 255, 0]]], 'RGB').tolist() == [[100, -1]]
    rgba = [[[0, 0, 0, 255], [255, 255, 255, 0], [128, 128, 128, 0], [254, 254, 254, 255]]]
    # trinary: the mean takes alpha in: 63.75 -> p 0.75; 191.25 -> 0.25; 96 -> 0.62; 254.25 -> 0.003.
    assert _load_pixels(tmp_path, rgba, 'RGBA').tolist() == [[100, -1, -1, 0]]
    # scale: alpha left out of the mean, and a transparent pixel between the thresholds is unknown.
    assert _load_pixels(tmp_path, rgba, 'RGBA', mode='scale').tolist() == [[100, 0, -1, 0]]


def test_a_palette_image_is_read_by_its_indices_as_sdl_hands_it_over(tmp_path):
    image = Image.new('P', (3, 1))
    image.putpalette([255, 255, 255, 0, 0, 0] + [0] * 762)  # index 0 white, index 1 black
    image.putdata([0, 1, 254])
    image.save(str(tmp_path / 'm.png'))
    # Indices 0 and 1 read as very dark: occupied, whatever the palette says; 254 free.
    assert map_files.load_map(str(_map_yaml(tmp_path))).values[0].tolist() == [100, 100, 0]


def test_ascii_pgm_and_a_small_maxval_scale_to_255(tmp_path):
    (tmp_path / 'm.pgm').write_bytes(b'P2\n# a comment\n3 1\n15\n0 15 12\n')  # 12 * 255 // 15 = 204: unknown
    assert map_files.load_map(str(_map_yaml(tmp_path, image='m.pgm'))).values.tolist() == [[100, 0, -1]]


def test_origin_and_relative_and_absolute_image_paths(tmp_path):
    Image.fromarray(np.zeros((2, 3), dtype=np.uint8)).save(str(tmp_path / 'm.png'))
    loaded = map_files.load_map(str(_map_yaml(tmp_path, origin='[1.5, -2, 0.3]')))
    assert loaded.grid == Grid(0.05, 3, 2, (1.5, -2.0, 0.3))
    elsewhere = tmp_path / 'elsewhere'
    elsewhere.mkdir()
    absolute = map_files.load_map(str(_map_yaml(elsewhere, image=str(tmp_path / 'm.png'))))
    assert np.array_equal(absolute.values, loaded.values)


def test_mode_is_optional_and_the_default_is_trinary(tmp_path):
    Image.fromarray(np.full((1, 1), 128, dtype=np.uint8)).save(str(tmp_path / 'm.png'))
    assert map_files.load_map(str(_map_yaml(tmp_path))).metadata.mode == 'trinary'


# --- errors: one line naming the file and the key ---------------------------------------------
@pytest.mark.parametrize('key', map_files.REQUIRED_KEYS)
def test_a_missing_key_is_named(tmp_path, key):
    Image.fromarray(np.zeros((1, 1), dtype=np.uint8)).save(str(tmp_path / 'm.png'))
    path = _map_yaml(tmp_path, **{key: None})
    with pytest.raises(MapFileError) as error:
        map_files.load_map(str(path))
    assert str(error.value).startswith("%s: key '%s': missing" % (path, key))
    assert error.value.key == key and '\n' not in str(error.value)


@pytest.mark.parametrize('key, value, says', [
    ('resolution', '-0.05', 'must be > 0'), ('resolution', '0', 'must be > 0'),
    ('resolution', 'fine', "not 'fine'"), ('resolution', '.nan', 'finite'),
    ('origin', '[1.0, 2.0]', '[x, y, yaw]'), ('origin', 'zero', '[x, y, yaw]'),
    ('negate', 'maybe', 'integer'), ('occupied_thresh', 'high', 'finite number'),
    ('free_thresh', '[0.2]', 'finite number'), ('mode', 'binary', 'trinary, scale, raw'),
    ('image', "''", 'name of an image'),
])
def test_a_bad_value_is_named_with_its_key(tmp_path, key, value, says):
    Image.fromarray(np.zeros((1, 1), dtype=np.uint8)).save(str(tmp_path / 'm.png'))
    path = _map_yaml(tmp_path, **{key: value})
    with pytest.raises(MapFileError, match=says) as error:
        map_files.load_map(str(path))
    assert str(error.value).startswith("%s: key '%s': " % (path, key))


def test_a_missing_or_unreadable_image_is_named(tmp_path):
    path = _map_yaml(tmp_path, image='nowhere.pgm')
    with pytest.raises(MapFileError) as error:
        map_files.load_map(str(path))
    assert str(error.value) == "%s: key 'image': image file %s does not exist" % (path, tmp_path / 'nowhere.pgm')
    (tmp_path / 'broken.png').write_bytes(b'not an image at all')
    with pytest.raises(MapFileError, match="key 'image': cannot read image file .*broken.png"):
        map_files.load_map(str(_map_yaml(tmp_path, image='broken.png')))
    (tmp_path / 'short.pgm').write_bytes(b'P5\n4 4\n255\n\x00\x00')
    with pytest.raises(MapFileError, match="key 'image': cannot read image file .*short.pgm"):
        map_files.load_map(str(_map_yaml(tmp_path, image='short.pgm')))


def test_a_missing_or_malformed_yaml_is_named(tmp_path):
    with pytest.raises(MapFileError, match='^%s: cannot open the map file' % (tmp_path / 'none.yaml')):
        map_files.load_map(str(tmp_path / 'none.yaml'))
    (tmp_path / 'bad.yaml').write_text('image: [unclosed\n')
    with pytest.raises(MapFileError, match='^%s: not valid YAML' % (tmp_path / 'bad.yaml')) as error:
        map_files.load_map(str(tmp_path / 'bad.yaml'))
    assert '\n' not in str(error.value)
    (tmp_path / 'list.yaml').write_text('- 1\n- 2\n')
    with pytest.raises(MapFileError, match='a mapping of the keys image, resolution'):
        map_files.load_map(str(tmp_path / 'list.yaml'))
