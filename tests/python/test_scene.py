# meltwater.Scene: the built-in dam break, files, dicts, overrides in every form, the resolved
# scene as a dict.
import json

import pytest

import meltwater

from conftest import REPO


def test_the_built_in_scene_is_scenes_dam_break():
    scene = meltwater.Scene()
    assert scene.name == "dam_break"
    assert scene.origin == "built-in"
    assert scene.source == "built-in default scene"
    from_file = meltwater.Scene(REPO / "scenes" / "dam_break.json")
    assert from_file.origin == "file"
    assert from_file.to_dict() == scene.to_dict()


def test_overrides_in_each_form_give_the_same_scene():
    as_text = meltwater.Scene(overrides=["fluid.spacing=0.04", "solver.dt_mode=fixed"])
    as_one_text = meltwater.Scene(overrides="fluid.spacing=0.04").with_overrides("solver.dt_mode=fixed")
    as_dict = meltwater.Scene(overrides={"fluid.spacing": 0.04, "solver.dt_mode": "fixed"})
    d = as_text.to_dict()
    assert d["fluid"]["spacing"] == 0.04
    assert d["solver"]["dt_mode"] == "fixed"
    assert as_one_text.to_dict() == d
    assert as_dict.to_dict() == d
    assert as_text.overrides == ["fluid.spacing=0.04", "solver.dt_mode=fixed"]
    # A key the scene does not give follows what it derives from, as with --set.
    assert d["fluid"]["support_radius"] == pytest.approx(0.08)


def test_a_dict_scene_with_an_override():
    numpy = pytest.importorskip("numpy")
    scene_dict = {
        "name": "little_box",
        "domain": {"min": [0, 0, 0], "max": [0.4, 0.4, 0.2]},
        "fluid": {"spacing": 0.04},
        # NumPy values are taken as the plain numbers they hold.
        "fluid_blocks": [{"min": [0, 0, 0], "max": numpy.array([0.2, 0.2, 0.2])}],
        "run": {"end_time": numpy.float32(0.25)},
    }
    scene = meltwater.Scene(scene_dict, overrides={"fluid_blocks.0.velocity": [0.5, 0, 0]})
    assert scene.origin == "dict"
    assert scene.source == "scene dict"
    assert scene.name == "little_box"
    assert scene.end_time == pytest.approx(0.25)
    d = scene.to_dict()
    assert d["fluid_blocks"][0]["velocity"] == [0.5, 0, 0]
    assert d["fluid_blocks"][0]["max"] == pytest.approx([0.2, 0.2, 0.2])
    # The resolved dict is itself a scene, and the same one.
    assert meltwater.Scene(d).to_dict() == d
    json.dumps(d)  # plain JSON values only


def test_the_schema_lists_every_key():
    keys = {row["key"] for row in meltwater.schema()}
    assert {"fluid.spacing", "solver.dt", "heat.enabled"} <= keys


def test_scene_arguments_of_the_wrong_kind_are_type_errors():
    with pytest.raises(TypeError):
        meltwater.Scene(42)
    with pytest.raises(TypeError):
        meltwater.Scene(overrides=[("fluid.spacing", 0.04)])
