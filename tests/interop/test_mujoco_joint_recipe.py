"""docs/mujoco.md's recipe for the sampling pad's calibration with the joint fit, run as
written: a probe sweep for the gains, presses of known force for the joint fit's force
curve (``joint_force_calibration``), then ``locate --method joint`` on a MuJoCo
recording of the ball held and sliding. Round 9's trial found ``locate`` there 12-15 %
off (the long table's lift re-zero under a sliding ball) and no runnable recipe."""

import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

DOC = Path(__file__).resolve().parents[2] / "docs" / "mujoco.md"
FLAWS = "gain_spread,noise,quantization,nonlinearity,dead,crosstalk"


def _doc_blocks():
    text = DOC.read_text()
    start = text.index("On your own pad, with presses of")
    bash, python = re.findall(r"```(?:bash|python)\n(.*?)```", text[start:], re.S)[:2]
    return bash, python


def _tactsense(*args, cwd):
    result = subprocess.run([sys.executable, "-m", "tactsense", *args], cwd=cwd,
                            capture_output=True, text=True, timeout=300)  # fmt: skip
    assert result.returncode == 0, result.stdout + result.stderr
    return result.stdout


def test_the_doc_recipe_reads_the_sliding_ball_within_two_percent(tmp_path):
    pytest.importorskip("mujoco")
    import pandas as pd

    from tactsense.interop.mujoco import example_pad_path
    from tactsense.io.recording import read_recording

    bash, python = _doc_blocks()
    pad = str(example_pad_path())
    # the doc's lines, with its variables, are the ones run here
    lines = [
        ["simulate", "--sensor", pad, "--scenario", "calibration", "--flaws", FLAWS,
         "-o", "sweep.h5"],
        ["calibrate", "sweep.h5", "-o", "gains.json"],
        ["simulate", "--sensor", pad, "--scenario", "loads", "--size-mm", "8", "--flaws", FLAWS,
         "--forces-g", "20,50,100,150,200,250,300", "-o", "presses.h5"],
    ]  # fmt: skip
    assert f"F={FLAWS}" in bash
    for args in lines:
        shown = " ".join('"$PAD"' if a == pad else "$F" if a == FLAWS else a for a in args)
        assert shown in " ".join(bash.replace("\\\n", " ").split()), shown
        _tactsense(*args, cwd=tmp_path)
    (tmp_path / "joint_cal.py").write_text(python)
    subprocess.run([sys.executable, "joint_cal.py"], cwd=tmp_path, check=True, timeout=300)
    # the example's ball pressed (1.5-1.8 s) and sliding (2.3-2.6 s) on the sampling pad
    _tactsense("mujoco", "--sensor", pad, "--seconds", "2.6", "--seed", "2", "--out",
               "thick.h5", cwd=tmp_path)  # fmt: skip
    assert "tactsense locate thick.h5 --method joint --calibration joint_cal.json" in bash
    _tactsense("locate", "thick.h5", "--method", "joint", "--calibration", "joint_cal.json",
               "-o", "est.csv", cwd=tmp_path)  # fmt: skip
    truth = np.asarray(read_recording(tmp_path / "thick.h5").truth["step_force_n"])
    table = pd.read_csv(tmp_path / "est.csv")
    summed = table.groupby("frame")["force_n"].sum()
    for first, last in ((150, 180), (230, 260)):  # held, sliding
        frames = np.arange(first, last)
        error = summed.reindex(frames).fillna(0.0).to_numpy() / truth[frames] - 1.0
        # the goal of issue 38 (2 %), every frame; measured here -0.7 % held, -0.5 % at
        # worst sliding (seed 2)
        assert np.all(np.abs(error) <= 0.02), (first, np.round(100 * error, 2))
