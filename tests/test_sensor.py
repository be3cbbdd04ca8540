import math

import pytest

import tactsense as ts
from tactsense.sensor import VACUUM_PERMITTIVITY, SensorSpec, SensorSpecError


def test_presets_match_the_paper(initial, improved):
    """The presets against the paper's text (sections 2.3, 3, 4.1), not against the code:
    3.8 mm x 45 deg and 3.3 mm x 18 deg spacings, 12 strips and 7 rings on the improved
    cylinder, the 1-inch finger on a 17.7-mm core, the 3.8-mm / nu = 0.4 fit, V_o = 2000."""
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


def test_ring_flexural_length_from_a_beam_on_an_elastic_foundation(initial):
    """The ring is a copper beam on the dielectric (a Winkler foundation): solve
    EI d4w/dx4 + k w = P delta(x) by finite differences and find the flexural length from
    where the deflection first crosses zero (beta x = 3 pi / 4 for the exact solution
    e^{-beta x} (cos beta x + sin beta x)), independently of the closed form the code uses.
    Foundation modulus k = E_d b / t_d, I = b t^3 / 12 (their definitions)."""
    import numpy as np

    rings = initial.rings
    b, t = rings.ring_width_mm * 1e-3, rings.ring_thickness_mm * 1e-3
    k = rings.dielectric_modulus_pa * b / (rings.dielectric_thickness_mm * 1e-3)
    ei = rings.copper_modulus_pa * b * t**3 / 12
    n, length = 4001, 0.04  # a beam much longer than the flexural length (about 1.4 mm)
    h = length / (n - 1)
    matrix = np.zeros((n, n))
    stencil = np.array([1.0, -4.0, 6.0, -4.0, 1.0]) * ei / h**4
    for i in range(2, n - 2):
        matrix[i, i - 2 : i + 3] = stencil
        matrix[i, i] += k
    for i in (0, 1, n - 2, n - 1):  # far ends: clamped at zero deflection
        matrix[i, :] = 0.0
        matrix[i, i] = 1.0
    load = np.zeros(n)
    load[n // 2] = 1.0 / h
    w = np.linalg.solve(matrix, load)
    right = w[n // 2 :]
    first_zero = np.flatnonzero(right < 0)[0] * h
    flexural_mm = 1e3 * first_zero / (3 * np.pi / 4)
    # the zero is located to one grid step (10 um of about 1.4 mm): 1 %
    assert initial.ring_flexural_length_mm == pytest.approx(flexural_mm, rel=0.01)


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
        (
            'extends = "bogus"\n',
            r"not a preset; available: initial \(finger\), improved \(finger\)",
        ),
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
