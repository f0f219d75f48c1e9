"""The scene description: validation names the key, geometry queries are right."""

import numpy as np
import pytest

from g1_control.errors import LaunchFileError
from g1_control.scene import Box, Platform, SceneConfig, Table


def _scene(**kw):
    d = dict(tables=[Table("table_a", (2.0, 0.0), (0.5, 0.8), 0.7)],
             platforms=[Platform("step", (0.0, 2.0), (0.6, 1.0), 0.15)],
             boxes=[Box("box", (1.9, 0.0), stands_on="table_a")])
    d.update(kw)
    return SceneConfig(**d)


def test_a_valid_scene_and_its_queries():
    s = _scene()
    s.validate("scene")
    assert s.box_center(s.boxes[0]) == pytest.approx([1.9, 0.0, 0.85])
    assert s.ground_height(np.array([0.0, 2.0])) == 0.15 and s.ground_height(np.array([1.0, 1.0])) == 0.0
    assert s.block("table_a").distance_xy(np.array([1.0, 0.0])) == pytest.approx(0.75)
    turned = Table("t", (0.0, 0.0), (1.0, 0.2), 0.7, yaw_rad=np.pi / 2)
    assert turned.contains_xy(np.array([0.0, 0.45])) and not turned.contains_xy(np.array([0.45, 0.0]))


@pytest.mark.parametrize("change, key", [
    (dict(boxes=[Box("box", (1.0, 0.0), stands_on="table_a")]), "scene.boxes[0].xy_m"),
    (dict(boxes=[Box("box", (1.9, 0.0), stands_on="shelf")]), "scene.boxes[0].stands_on: 'shelf'"),
    (dict(boxes=[Box("table_a", (1.9, 0.0), stands_on="table_a")]), "scene.boxes[0].name: 'table_a' is already used"),
    (dict(platforms=[Platform("step", (0.3, 0.0), (0.4, 0.4), 0.15)]), "scene.platforms[0] (step): closer than"),
    (dict(boxes=[Box("box", (1.9, 0.0), stands_on="table_a", mass_kg=-1.0)]), "scene.boxes[0].mass_kg"),
    (dict(tables=[Table("Table A", (2.0, 0.0), (0.5, 0.8), 0.7)]), "scene.tables[0].name"),
])
def test_bad_scenes_are_refused_naming_the_key(change, key):
    with pytest.raises(LaunchFileError) as err:
        s = _scene(**change)
        for kind in ("tables", "platforms", "boxes"):
            for i, item in enumerate(getattr(s, kind)):
                item.validate(f"scene.{kind}[{i}]")
        s.validate("scene")
    assert key in str(err.value)
