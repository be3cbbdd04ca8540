import math

import pytest

import tactsense as ts
from tactsense.sensor import VACUUM_PERMITTIVITY, SensorSpec, SensorSpecError


def test_presets_match_the_paper(initial, improved):
    assert initial.shape == (8, 8) and improved.shape == (8, 8)
    assert initial.array.spacing_axial_mm == 3.8 and initial.array.spacing_angle_deg == 45
    assert improved.array.spacing_axial_mm == 3.3 and improved.array.spacing_angle_deg == 18
    assert improved.array.cols == 12 and improved.array.cylinder_rows == 7
    assert initial.closes_circumference and not improved.closes_circumference
    assert initial.body.diameter_mm == 25.4 and initial.body.core_diameter_mm == 17.7
    assert initial.elastic.effective_depth_mm == 3.8
    assert initial.elastic.effective_poisson_ratio == 0.4
    assert initial.electronics.nominal_counts == 2000


def test_junction_capacitance_is_about_one_picofarad(initial):
    # section 2.2: 2.5 mm x 5.1 mm plates 0.5 mm apart, K = 4: "about 1 pF"
    expected = 4 * VACUUM_PERMITTIVITY * 2.5e-3 * 5.1e-3 / 0.5e-3
    assert initial.junction_capacitance_f == pytest.approx(expected, rel=1e-12)
    assert 0.8e-12 < initial.junction_capacitance_f < 1.2e-12


def test_ring_flexural_length_formula(initial):
    # Hetenyi: lambda = (k / 4EI)^(1/4), k = E_d b / t_d, I = b t^3 / 12
    b, t = 2.5e-3, 0.07e-3
    k = 7e4 * b / 0.5e-3
    ei = 1.2e11 * b * t**3 / 12
    assert initial.ring_flexural_length_mm == pytest.approx(1e3 * (4 * ei / k) ** 0.25, rel=1e-12)


def test_wired_columns_of_improved_finger_are_central(improved):
    assert list(improved.col_angle_deg) == [-63, -45, -27, -9, 9, 27, 45, 63]


def test_toml_round_trip(any_preset, tmp_path):
    path = any_preset.to_toml(tmp_path / "finger.toml")
    assert SensorSpec.from_toml(path) == any_preset


def test_to_toml_never_overwrites(initial, tmp_path):
    path = tmp_path / "finger.toml"
    path.write_text("keep me")
    with pytest.raises(FileExistsError):
        initial.to_toml(path)
    assert path.read_text() == "keep me"


def test_custom_sensor_from_partial_toml():
    spec = SensorSpec.from_toml_string(
        'name = "mine"\nextends = "initial"\n'
        "[array]\nspacing_axial_mm = 3.0\n[elastic]\neffective_depth_mm = 2.5\n"
    )
    assert spec.name == "mine"
    assert spec.array.spacing_axial_mm == 3.0 and spec.elastic.effective_depth_mm == 2.5


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("[array]\nspacing_axial_mmm = 3.0\n", "unknown key 'spacing_axial_mmm' in \\[array\\]"),
        ("colour = 'red'\n", "unknown key 'colour' at top level"),
        ("[array]\nspacing_axial_mm = -3.0\n", "spacing_axial_mm must be positive"),
        ("[array]\nspacing_axial_mm = 0\n", "spacing_axial_mm must be positive"),
        (
            "[elastic]\neffective_poisson_ratio = 0.7\n",
            "effective_poisson_ratio = 0.7 is out of range",
        ),
        ("[array]\nwired_rows = 9\n", "wired_rows = 9 is larger than the array"),
        ("[array]\nwired_cols = 9\n", "do not fit in the array of 8 columns"),
        ("[array]\ncols = 9\n", "more than the full circle"),
        ("[array]\ncylinder_rows = 7\nspacing_axial_mm = 5.0\n", "do not fit on the cylinder"),
        ("[array]\nwired_rows = 'eight'\n", "expected an integer"),
        ("[flaws]\ndead_tactels = [[9, 0]]\n", "outside the wired array"),
        ("[elastic]\nmodel = 'plane'\n", "model = 'plane'"),
        ("[array\n", "not valid TOML"),
    ],
)
def test_validation_says_what_is_wrong(text, message):
    with pytest.raises(SensorSpecError, match=message):
        SensorSpec.from_toml_string('extends = "initial"\n' + text)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("", "no sections"),
        ('name = "x"\n', "no sections"),
        ("[array]\nspacing_axial_mm = 3.0\n", r"\[array\] is missing cylinder_rows, cols"),
        ("[array]\nspacing_axial_mm = 3.0\n", r"\[elastic\] is missing"),
        ('extends = "bogus"\n', "not a preset; available: initial, improved"),
        ("extends = 3\n", "not a preset"),
    ],
)
def test_missing_keys_are_an_error_unless_a_preset_is_extended(text, message):
    with pytest.raises(SensorSpecError, match=message):
        SensorSpec.from_toml_string(text)


def test_extends_takes_the_rest_from_the_preset():
    spec = SensorSpec.from_toml_string(
        'extends = "improved"\n[elastic]\neffective_depth_mm = 2.0\n'
    )
    expected = ts.fearing1990_improved().replace(elastic__effective_depth_mm=2.0)
    assert spec.array == expected.array and spec.elastic == expected.elastic
    assert spec.flaws == expected.flaws and spec.rings == expected.rings


def test_all_problems_reported_at_once():
    with pytest.raises(SensorSpecError) as info:
        SensorSpec.from_toml_string("[array]\nfoo = 1\nbar = 2\n")
    assert "foo" in str(info.value) and "bar" in str(info.value)


def test_replace_and_preset_lookup(initial):
    deeper = initial.replace(elastic__effective_depth_mm=5.0)
    assert deeper.elastic.effective_depth_mm == 5.0 and initial.elastic.effective_depth_mm == 3.8
    assert ts.preset("fearing1990_improved") == ts.fearing1990_improved()
    with pytest.raises(SensorSpecError, match="unknown preset"):
        ts.preset("nope")
    with pytest.raises(SensorSpecError, match="wired_rows"):
        initial.replace(array__wired_rows=20)


def test_missing_file_is_a_clear_error(tmp_path):
    with pytest.raises(SensorSpecError, match="cannot read sensor file"):
        SensorSpec.from_toml(tmp_path / "absent.toml")


def test_tip_row_lies_on_hemisphere(initial):
    assert -math.pi * initial.radius_mm / 2 <= initial.row_axial_mm[0] < 0
