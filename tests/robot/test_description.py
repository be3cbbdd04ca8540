"""A skin's description in TOML: the round trip and every error path."""

import math
import tomllib

import pytest
import tomli_w

from tactsense.robot import (
    RobotSkinError,
    load_skin,
    skin_from_dict,
    skin_from_toml,
    skin_preset,
    skin_to_dict,
    skin_to_toml_string,
)


@pytest.mark.parametrize("name", ["hand4", "icub_hand"])
def test_toml_round_trip_is_exact(tmp_path, name):
    """TOML carries floats in full (tomli_w writes repr), so the skin comes back equal."""
    skin = skin_preset(name)
    path = tmp_path / "skin.toml"
    path.write_text(skin_to_toml_string(skin))
    back = skin_from_toml(path)
    assert back == skin
    assert load_skin(path) == skin and load_skin(name) == skin


def _good() -> dict:
    return {
        "name": "s",
        "base_link": "a",
        "links": ["a", "b", "c"],
        "joints": [
            {"name": "j1", "type": "revolute", "parent": "a", "child": "b", "lower": -1.0,
             "upper": 1.0, "axis": [0, 0, 1]},
            {"name": "j2", "type": "fixed", "parent": "b", "child": "c", "xyz_m": [0.01, 0, 0]},
        ],
        "sensors": [{"name": "p", "link": "c", "sensor": "pad4", "device": "board"}],
    }  # fmt: skip


def test_the_good_description_reads():
    skin = skin_from_dict(_good())
    assert skin.movable_joints == ("j1",) and skin.patch("p").device == "board"
    assert skin.joints[1].lower == -math.inf


def _edit(change):
    data = _good()
    change(data)
    return data


ERRORS = [
    # (what is changed, what the message must say)
    (lambda d: d.update(colour="red"), "unknown key(s) colour"),
    (lambda d: d["joints"][0].update(damping=1), "joints[0]: unknown key(s) damping"),
    (lambda d: d["sensors"][0].update(pose=1), "sensors[0]: unknown key(s) pose"),
    (lambda d: d.pop("base_link"), "missing 'base_link'"),
    (lambda d: d["joints"][0].pop("child"), "joints[0]: missing 'child'"),
    (lambda d: d["sensors"][0].pop("sensor"), "sensors[0]: missing 'sensor'"),
    (lambda d: d["joints"][0].update(lower="low"), "lower = 'low'; expected a number"),
    (lambda d: d["joints"][0].update(lower=2.0), "lower limit 2.0 is above upper limit 1.0"),
    (lambda d: d["joints"][0].update(upper=math.nan), "upper limit nan is not a number"),
    (lambda d: d["joints"][0].update(type="floating"), "type 'floating'; expected one of"),
    (lambda d: d["joints"][0].update(axis=[0, 0, 0]), "axis is zero"),
    (lambda d: d["joints"][0].update(axis=[0, 1]), "axis = [0, 1]: expected three"),
    (lambda d: d["joints"][1].update(xyz_m=[0, "x", 0]), "joints[1]: xyz_m = [0, 'x', 0]"),
    (lambda d: d["joints"][0].update(name=3), "name = 3; expected a string"),
    (lambda d: d.update(joints={"a": 1}), "joints is a dict; expected an array of tables"),
    (lambda d: d.update(links="a b c"), "links = 'a b c'; expected an array of names"),
    (lambda d: d["joints"][1].update(child="b"), "link 'b' is the child of two joints"),
    (lambda d: d["joints"][1].update(parent="nowhere"), "link 'nowhere' is not one of"),
    (lambda d: d["sensors"][0].update(link="nowhere"), "patch 'p': link 'nowhere' is not"),
    (lambda d: d["joints"][0].update(child="a"), "base_link 'a' is a joint's child"),
    (
        lambda d: (d["links"].append("d"), d["joints"].append(
            {"name": "j3", "type": "fixed", "parent": "d", "child": "c"})),
        "link 'c' is the child of two joints",
    ),
    (
        lambda d: (d["links"].extend(["x", "y"]), d["joints"].extend([
            {"name": "k1", "type": "fixed", "parent": "x", "child": "y"},
            {"name": "k2", "type": "fixed", "parent": "y", "child": "x"}])),
        "the joints close a loop: x -> y -> x",
    ),
    (lambda d: d["links"].append("lonely"), "links not joined to the base: lonely"),
    (lambda d: d["links"].append("a"), "link(s) named twice: 'a'"),
    (lambda d: d["joints"][1].update(name="j1"), "joint 'j1' is named twice"),
    (lambda d: d["sensors"].append(dict(d["sensors"][0])), "patch 'p' is named twice"),
    (lambda d: d.update(sensors=[]), "no sensors"),
    (lambda d: d["sensors"][0].update(name="my pad"), "patch name 'my pad'"),
    (lambda d: d["sensors"][0].update(device="b=1"), "device name 'b=1'"),
    (lambda d: (d["links"].append("a b"), d["joints"].append(
        {"name": "j4", "type": "fixed", "parent": "c", "child": "a b"})), "name 'a b'"),
    (lambda d: d["sensors"][0].update(sensor="pad99"), "neither a preset"),
    (lambda d: d["sensors"][0].update(sensor="missing.toml"), "does not exist"),
    (lambda d: d["sensors"][0].update(sensor={"kind": "pad", "grid": {"rows": 0}}),
     "sensors[0] (p)"),
    (lambda d: d["sensors"][0].update(sensor=5), "expected a preset's name"),
]  # fmt: skip


@pytest.mark.parametrize("change, message", ERRORS, ids=[m for _, m in ERRORS])
def test_every_error_says_what_and_where(tmp_path, change, message):
    data = _edit(change)
    with pytest.raises(RobotSkinError) as caught:
        skin_from_dict(data, source="skin.toml", folder=tmp_path)
    assert message in str(caught.value)
    # and the same through a file, when TOML can hold it
    try:
        text = tomli_w.dumps(data)
    except (TypeError, ValueError):
        return
    path = tmp_path / "skin.toml"
    path.write_text(text)
    assert tomllib.loads(text) is not None
    with pytest.raises(RobotSkinError, match=r"skin\.toml"):
        skin_from_toml(path)


def test_file_errors(tmp_path):
    with pytest.raises(RobotSkinError, match="does not exist"):
        skin_from_toml(tmp_path / "none.toml")
    (tmp_path / "bad.toml").write_text("name = ")
    with pytest.raises(RobotSkinError, match="not TOML"):
        skin_from_toml(tmp_path / "bad.toml")
    with pytest.raises(RobotSkinError, match="neither a preset"):
        load_skin("hand5")


def test_the_dict_form_names_every_sensor_whole():
    data = skin_to_dict(skin_preset("icub_hand"))
    assert data["sensors"][0]["sensor"]["name"] == "icub_fingertip"
    assert data["joints"][0]["lower"] == 0.0 and "lower" not in data["joints"][4]  # fixed
