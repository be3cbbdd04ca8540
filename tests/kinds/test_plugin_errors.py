"""A plug-in kind's bad description is the user's error, said in words, never a
traceback: the toy kind checks through ``problems()`` as docs/kinds.md shows, and a kind
whose description refuses by raising ``ValueError`` is still turned into one error."""

from __future__ import annotations

import subprocess
import sys

import pytest
import toy_kind

from tactsense.sensor import SensorSpecError, sensor_from_dict


def test_a_bad_lattice_names_every_problem_without_a_traceback(tmp_path, cli_env):
    bad = tmp_path / "bad.toml"
    bad.write_text(
        'kind = "hexpatch"\nname = "bad"\nextends = "hex19"\n'
        "[lattice]\nrings = -1\npitch_mm = -3.0\n"
    )
    done = subprocess.run(
        [sys.executable, "-m", "tactsense", "sensor", "check", str(bad)],
        env=cli_env, capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert done.returncode == 2, done.stderr
    assert "Traceback" not in done.stderr + done.stdout
    assert "[lattice] rings = -1: expected an integer from 0 to 20" in done.stderr
    assert "[lattice] pitch_mm = -3.0: expected a positive number" in done.stderr


def test_a_description_that_raises_is_one_sensor_error(monkeypatch):
    def refuse(self):
        raise ValueError("[lattice] rings: no such lattice")

    monkeypatch.setattr(toy_kind.HexPatchSpec, "__post_init__", refuse)
    with pytest.raises(SensorSpecError, match=r"invalid hexpatch description: \[lattice\]"):
        sensor_from_dict({"kind": "hexpatch", "extends": "hex19"}, source="lab.toml")
