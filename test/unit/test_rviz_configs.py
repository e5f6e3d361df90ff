"""Every rviz config shipped leaves room for the 3D view.

rviz lays its panels out from the config's Window Geometry. Without a
`QMainWindow State`, every panel the config lists goes into the left dock, one
under another; with ROBOTIS' five (Displays, Selection, Tool Properties, Views,
Time) that dock took the whole 1280 px window and the map was never drawn
(test_emanual, CI, 2026-11-27). Displays and Views alone leave the view its room.
"""
import glob
import os

import pytest
import yaml

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
CONFIGS = sorted(glob.glob(os.path.join(ROOT, 'rviz', '*.rviz')) +
                 glob.glob(os.path.join(ROOT, 'packages', '*', 'rviz', '*.rviz')))
DOCKED_SAFELY = {'rviz/Displays', 'rviz/Views'}


def test_the_configs_are_found():
    assert len(CONFIGS) >= 10


@pytest.mark.parametrize('path', CONFIGS, ids=[os.path.relpath(path, ROOT) for path in CONFIGS])
def test_a_config_with_more_panels_says_where_they_go(path):
    with open(path) as stream:
        config = yaml.safe_load(stream)
    panels = {panel['Class'] for panel in config.get('Panels', [])}
    geometry = config['Window Geometry']
    if panels - DOCKED_SAFELY:
        assert geometry.get('QMainWindow State'), (
            '%s lists the panels %s but no QMainWindow State: rviz stacks them over the 3D view'
            % (path, sorted(panels - DOCKED_SAFELY)))
