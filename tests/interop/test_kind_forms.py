"""The LSL and URDF forms are asked of the sensor's kind (issue 33)."""

import numpy as np
import pytest

from tactsense.interop.urdf import UrdfError, sensor_from_urdf_any, sensor_to_urdf
from tactsense.kinds import Kind, KindNotSupported, kind_of
from tactsense.sensor import preset


def test_only_a_pad_is_written_as_an_array():
    pad = preset("pad16")
    array = kind_of(pad).urdf_array(pad)
    assert (array["rows"], array["cols"]) == pad.shape
    assert array["spacing_mm"] == (pad.grid.row_pitch_mm, pad.grid.col_pitch_mm)
    for name in ("initial", "dome12"):
        spec = preset(name)
        assert kind_of(spec).urdf_array(spec) is None
        assert len(kind_of(spec).urdf_taxels(spec)) == spec.n_taxels


def test_the_fingers_channels_carry_its_surface_coordinates():
    finger = preset("initial")
    fields = kind_of(finger).lsl_taxel_fields(finger)
    rows, cols = finger.shape
    axial = fields["axial_mm"].reshape(rows, cols)
    angle = fields["angle_deg"].reshape(rows, cols)
    assert np.array_equal(axial[:, 0], finger.row_axial_mm)
    assert np.array_equal(angle[0], finger.col_angle_deg)
    assert kind_of(preset("pad16")).lsl_taxel_fields(preset("pad16")) == {}


def test_a_kind_without_a_form_says_so():
    class Ring(Kind):
        name = "ring"
        spec_class = object

    ring, pad = Ring(), preset("pad16")
    assert ring.from_urdf_array(None, pad, path="x.urdf", preset="pad16") is None
    assert ring.from_urdf_taxels(None, pad, path="x.urdf") is None
    with pytest.raises(KindNotSupported, match="URDF <taxel> list"):
        ring.urdf_taxels(pad)  # a pad has no taxel areas


def test_a_form_the_preset_kind_does_not_read_is_one_line(tmp_path):
    path = tmp_path / "pad.urdf"
    path.write_text(sensor_to_urdf(preset("pad16")))
    with pytest.raises(UrdfError, match=r"is an <array>; extend a finger or a pad"):
        sensor_from_urdf_any(path, extends="dome12")
    assert sensor_from_urdf_any(path, extends="pad4").shape == preset("pad16").shape
