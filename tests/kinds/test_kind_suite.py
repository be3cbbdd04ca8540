"""The kind suite: what every registered sensor kind must pass, end to end, as a user
runs it (issue 33, item 2; as scikit-learn's ``check_estimator`` is for estimators).

Parametrized over ``tactsense.kinds.kinds()``: the built-in finger, pad and point set,
and every kind a package registers through the ``tactsense.kinds`` entry-point group,
among them the toy hexagonal patch of ``tests/kinds/toy_kind.py`` (registered by
``conftest.py`` through a real ``toy_kind-0.0.dist-info``). For a preset of each kind
(the first of ``Kind.presets``), every step is a command (``python -m tactsense``):

* ``sensor show`` and ``sensor check`` on the preset's TOML, ``sensor show`` by preset name;
* ``simulate`` (the kind's default scenario: a press, or the finger's probe sweep);
* ``emulate`` the device and ``record`` from it: the frames the simulation wrote;
* ``locate``: the contacts lie near the pressed spots (:data:`TOLERANCE`);
* ``calibrate`` on the kind's calibration scenario, then ``locate --calibration``; a kind
  without a calibration says so in a one-line error, ``kind.unsupported``'s;
* ``view``: the page's layout and frame messages build for the recording (no browser);
* ``export`` to CSV and to MCAP and ``import`` back: the same frames, times and sensor.
"""

from __future__ import annotations

import csv
import dataclasses
import json
import subprocess
import sys
import textwrap
import tomllib
from pathlib import Path

import numpy as np
import pytest

from tactsense.kinds import kind_of, kinds

TOLERANCE = {"mm": 1.25, "deg": 5.0}
"""Largest median distance [the coordinate's unit] of a located contact from the pressed
spot, per coordinate; no frame may be off by more than twice it. (The finger's taxels are
3.8 mm x 45 deg apart, pad16's 2.5 mm, the point sets' 3-4 mm.)"""

RECORDED = 40
"""Frames recorded from the emulator."""

TIMEOUT_S = 300


def first_preset(kind):
    """The preset the suite runs on: the first of the kind's own; else the first built-in
    preset of that kind (until every kind names its presets)."""
    if kind.presets:
        return next(iter(kind.presets.values()))()
    from tactsense.sensor.registry import PRESETS

    for make in PRESETS.values():
        spec = make()
        if kind.describes(spec):
            return spec
    pytest.fail(f"kind {kind.name!r} has no preset")


def tactsense(env, *args, cwd, ok: bool = True) -> subprocess.CompletedProcess:
    """``python -m tactsense ARGS`` as a user runs it."""
    done = subprocess.run(
        [sys.executable, "-m", "tactsense", *map(str, args)],
        cwd=cwd,
        env=env,
        capture_output=True,
        text=True,
        timeout=TIMEOUT_S,
    )
    if ok:
        assert done.returncode == 0, (
            f"tactsense {' '.join(map(str, args))} failed ({done.returncode}):\n"
            f"{done.stdout[-3000:]}\n{done.stderr[-3000:]}"
        )
    return done


def one_line_error(done: subprocess.CompletedProcess) -> str:
    """The command failed with one line on stderr, ``error: ...``, and no traceback."""
    assert done.returncode != 0
    said = done.stderr.strip()
    assert "Traceback" not in said, said
    assert said.startswith("error:"), said
    assert len(said.splitlines()) == 1, said
    return said


def unsupported(case) -> str:
    """What ``kind.unsupported(spec, what)`` says of the sensor, whatever ``what``."""
    return str(case.kind.unsupported(case.spec, "")).strip()


@dataclasses.dataclass
class Case:
    kind: object
    spec: object
    dir: Path
    env: dict
    toml: Path

    def run(self, *args, ok: bool = True) -> subprocess.CompletedProcess:
        return tactsense(self.env, *args, cwd=self.dir, ok=ok)


@pytest.fixture(scope="module", params=sorted(kinds()), ids=str)
def case(request, tmp_path_factory, cli_env) -> Case:
    kind = kinds()[request.param]
    spec = first_preset(kind)
    where = tmp_path_factory.mktemp(f"kind_{kind.name}")
    toml = where / f"{spec.name}.toml"
    toml.write_text(spec.to_toml_string())
    return Case(kind, spec, where, cli_env, toml)


@pytest.fixture(scope="module")
def simulated(case) -> Path:
    path = case.dir / "sim.h5"
    case.run("simulate", "--sensor", case.toml, "-o", path)
    return path


def read(path: Path):
    from tactsense.io.recording import read_recording

    return read_recording(path)


# ---- what the kind is -------------------------------------------------------------


def test_the_toy_kind_comes_through_its_entry_point(cli_env):
    """Not through an import of tests/kinds/toy_kind.py: importlib.metadata finds the
    toy_kind-0.0.dist-info, in this process and in a command's."""
    from importlib.metadata import entry_points

    from tactsense.kinds import GROUP

    (point,) = [ep for ep in entry_points(group=GROUP) if ep.name == "hexpatch"]
    assert point.value == "toy_kind:KIND"
    assert point.dist.name == "toy-kind"
    assert kinds()["hexpatch"] is point.load()
    listed = subprocess.run(
        [sys.executable, "-c", "from tactsense.kinds import kinds; print(*kinds())"],
        env=cli_env, capture_output=True, text=True, timeout=TIMEOUT_S, check=True,
    ).stdout.split()  # fmt: skip
    assert listed[:3] == ["finger", "pad", "points"] and "hexpatch" in listed


def test_the_kind_is_registered_and_describes_its_preset(case):
    kind, spec = case.kind, case.spec
    assert kind_of(kind.name) is kind
    assert kind_of(spec) is kind
    assert kind.describes(spec)
    assert kind.name == kind.spec_class.kind == spec.kind
    assert kind.label and kind.plural
    assert len(kind.position_names) == len(kind.position_units) == 2
    assert set(kind.position_units) <= set(TOLERANCE)
    # no other kind claims its sensors
    assert [k.name for k in kinds().values() if k.describes(spec)] == [kind.name]


def test_the_kind_names_its_presets(case):
    assert case.kind.presets, f"{case.kind!r} names no preset (Kind.presets)"
    for name, make in case.kind.presets.items():
        assert kind_of(make()) is case.kind, name


def test_its_description_round_trips_through_toml(case):
    spec = case.spec
    data = tomllib.loads(spec.to_toml_string())
    assert type(spec).from_dict(data) == spec


# ---- the commands -------------------------------------------------------------------


def test_sensor_show_and_check(case):
    shown = case.run("sensor", "show", "--sensor", case.toml).stdout
    assert type(case.spec).from_dict(tomllib.loads(shown)) == case.spec
    checked = case.run("sensor", "check", case.toml)
    assert case.spec.name in checked.stdout


def test_its_presets_are_known_by_name(case):
    """``--sensor NAME`` finds the kind's presets, as it finds the built-in ones."""
    for name, make in case.kind.presets.items():
        shown = case.run("sensor", "show", "--sensor", name).stdout
        assert type(case.spec).from_dict(tomllib.loads(shown)) == make(), name


def test_simulate_writes_frames_of_the_sensor_and_the_truth(case, simulated):
    recording = read(simulated)
    assert recording.sensor == case.spec
    assert kind_of(recording.sensor) is case.kind
    assert recording.frames.shape[1:] == case.spec.frame_shape
    assert len(recording.frames) > 20
    truth = recording.truth
    for name in case.kind.position_names:
        assert f"step_{name}" in truth, sorted(truth)
    assert (truth["step_n_contacts"] > 0).any()


def test_emulate_then_record_gives_the_simulated_frames(case, simulated):
    emulator = subprocess.Popen(
        [sys.executable, "-m", "tactsense", "emulate", "--sensor", str(case.toml),
         "--port", "0", "--speed", "1e6"],
        cwd=case.dir, env=case.env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    try:
        url = emulator.stdout.readline().strip()
        assert url.startswith("socket://127.0.0.1:"), (url, emulator.stderr.read())
        out = case.dir / "live.h5"
        case.run("record", url, "-o", out, "--frames", RECORDED, "--quiet")
    finally:
        emulator.terminate()
        emulator.wait(timeout=30)
    live, simulation = read(out), read(simulated)
    assert kind_of(live.sensor) is case.kind
    assert live.sensor.name == case.spec.name and live.sensor.shape == case.spec.shape
    np.testing.assert_array_equal(live.frames, simulation.frames[:RECORDED])


def located_errors(kind, table: Path, recording) -> np.ndarray:
    """Per located contact in a frame pressed by one indenter: |found - pressed| per
    coordinate of ``kind.position_names``."""
    step = recording.truth["frame_step"]
    single = recording.truth["step_n_contacts"] == 1
    errors = []
    with table.open() as f:
        for row in csv.DictReader(f):
            frame = int(row["frame"])
            if not single[step[frame]]:
                continue
            found = np.array([float(row[name] or "nan") for name in kind.position_names])
            if not np.isfinite(found).all():
                continue
            pressed = [recording.truth[f"step_{name}"][step[frame]] for name in kind.position_names]
            errors.append(np.abs(found - pressed))
    return np.array(errors).reshape(-1, 2)


def assert_near(kind, errors: np.ndarray) -> None:
    assert len(errors) >= 5, f"only {len(errors)} frames located under a single press"
    tolerance = np.array([TOLERANCE[unit] for unit in kind.position_units])
    median = np.median(errors, axis=0)
    assert (median < tolerance).all(), (kind.position_names, median, tolerance)
    assert (errors.max(axis=0) < 2 * tolerance).all(), (errors.max(axis=0), tolerance)


def test_locate_finds_the_contacts_where_they_were_pressed(case, simulated):
    out = case.dir / "contacts.csv"
    case.run("locate", simulated, "-o", out)
    assert_near(case.kind, located_errors(case.kind, out, read(simulated)))


def test_calibrate_or_say_there_is_none(case, simulated):
    sweep = case.dir / "calibration.h5"
    made = case.run("simulate", "--sensor", case.toml, "--scenario", "calibration", "-o", sweep,
                    ok=False)  # fmt: skip
    if made.returncode != 0:
        said = one_line_error(made)
        assert unsupported(case) in said, said
        return
    calibration = case.dir / "calibration.json"
    done = case.run("calibrate", sweep, "-o", calibration, ok=False)
    if done.returncode != 0:
        said = one_line_error(done)
        assert unsupported(case) in said, said
        return
    assert calibration.is_file()
    out = case.dir / "calibrated.csv"
    case.run("locate", simulated, "--calibration", calibration, "-o", out)
    assert_near(case.kind, located_errors(case.kind, out, read(simulated)))


VIEW = textwrap.dedent(
    """
    import json, sys, time
    from tactsense.view.feed import RecordingFeed, view_locator
    from tactsense.view.vectors import baseline_of  # r8-triview: any frame shape

    def locator_for(spec, file):
        start = file.frames(0, 5)
        return view_locator(spec, baseline=baseline_of(start, min(5, len(start))))

    feed = RecordingFeed(sys.argv[1], locator_for, speed=1e6)
    layout = feed.layout()
    frames = []
    def publish(text):
        message = json.loads(text)
        if message["type"] == "frame":
            frames.append(message)
    feed.start(publish)
    deadline = time.monotonic() + 120
    while feed.status != "ended" and time.monotonic() < deadline:
        time.sleep(0.02)
    feed.stop()
    estimates = [m["estimate"] for m in frames if m["estimate"]]
    touched = sum(bool(e.get("contacts")) or e.get(sys.argv[2]) is not None for e in estimates)
    print(json.dumps({"layout": layout, "frames": len(frames), "touched": touched,
                      "status": feed.status}))
    """
)


def test_view_builds_the_layout_and_the_frames(case, simulated):
    done = subprocess.run(
        [sys.executable, "-c", VIEW, str(simulated), case.kind.position_names[0]],
        cwd=case.dir, env=case.env, capture_output=True, text=True, timeout=TIMEOUT_S,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    said = json.loads(done.stdout.strip().splitlines()[-1])
    layout = said["layout"]
    assert layout["type"] == "layout"
    assert layout["kind"] == case.kind.name and layout["sensor"] == case.spec.name
    assert (layout["rows"], layout["cols"]) == case.spec.shape
    assert layout["multi_contact"] == case.kind.multi_contact
    assert layout["estimation"] is None  # contacts are estimated on every kind
    assert said["status"] == "ended"
    assert said["frames"] == len(read(simulated).frames)
    assert said["touched"] >= 5


@pytest.mark.parametrize("form", ["csv", "mcap"])
def test_export_then_import_gives_the_frames_back(case, simulated, form):
    exported = case.dir / f"exported.{form}"
    case.run("export", simulated, "--format", form, "-o", exported, "--quiet", "--force")
    back = case.dir / f"imported_{form}.h5"
    case.run("import", exported, "--sensor", case.toml, "-o", back, "--force")
    original, imported = read(simulated), read(back)
    assert imported.sensor == original.sensor
    np.testing.assert_array_equal(imported.frames, original.frames)
    np.testing.assert_allclose(imported.time_s, original.time_s, rtol=0, atol=1e-6)
