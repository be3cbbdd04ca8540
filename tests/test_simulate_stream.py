"""``simulate_to_file`` (issue 21, item 7): the recording ``simulate`` makes, written as
it is made, in memory that does not grow with its length."""

import tracemalloc

import numpy as np
import pytest

import tactsense as ts
from tactsense.simulate import simulate_to_file


def _equal(a, b) -> bool:
    if isinstance(a, str):
        return a == b
    return np.array_equal(np.asarray(a), np.asarray(b), equal_nan=True)


SCENES = {
    "sweep": lambda spec: ts.probe_sweep(spec),
    "repeated": lambda spec: ts.repeated_load(spec, repeats=200),  # 2,800 frames: 3 chunks
    "knife": lambda spec: ts.knife_edge_sweep(spec),
    "calibration": lambda spec: ts.calibration_sweep(spec),
}


@pytest.mark.parametrize("flaws", ["all", "none"])
@pytest.mark.parametrize("name", list(SCENES))
def test_the_file_holds_what_simulate_returns(tmp_path, name, flaws):
    """Exactly (the same arithmetic and the same draws in the same order): frames,
    times, truth, gains and the scenario."""
    spec = ts.fearing1990_initial()
    scene = SCENES[name](spec)
    expected = ts.simulate(spec, scene, flaws=flaws, rng=5)
    n = simulate_to_file(spec, scene, tmp_path / "s.h5", flaws=flaws, rng=5)
    got = ts.read_recording(tmp_path / "s.h5")
    assert n == len(expected) == len(got)
    assert got.frames.dtype == expected.frames.dtype
    assert np.array_equal(got.frames, expected.frames)
    assert np.array_equal(got.time_s, expected.time_s)
    assert np.array_equal(got.gains, expected.gains)
    assert got.scenario == expected.scenario and got.flaws == expected.flaws
    assert set(got.truth) == set(expected.truth)
    assert all(_equal(got.truth[k], expected.truth[k]) for k in expected.truth)


def test_an_existing_file_is_refused_and_an_interrupted_run_leaves_nothing(tmp_path):
    spec = ts.fearing1990_initial()
    (tmp_path / "x.h5").write_text("keep")
    with pytest.raises(FileExistsError):
        simulate_to_file(spec, ts.probe_sweep(spec), tmp_path / "x.h5")
    assert (tmp_path / "x.h5").read_text() == "keep"

    def stop(done, total):
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        simulate_to_file(
            spec, ts.repeated_load(spec, repeats=200), tmp_path / "y.h5", progress=stop
        )
    assert not (tmp_path / "y.h5").exists()


def _peak_bytes(function) -> int:
    tracemalloc.start()
    try:
        function()
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


def test_memory_does_not_grow_with_the_length(tmp_path):
    """Four times the frames of one held probe (the scenario the same size), the same
    peak (NumPy's buffers are traced by tracemalloc): frames, their times and the step
    of each frame are never held whole. Holding the frames would add 28,000 x 64 x 2
    bytes (3.6 MB) at the longer length; the peak may grow by 0.2 MB."""
    spec = ts.fearing1990_initial()
    flaws = "gain_spread,jitter,noise,quantization,nonlinearity,dead"  # memory: no creep
    peaks = []
    for seconds in (1000, 4000):  # 7,000 and 28,000 frames
        path = tmp_path / f"r{seconds}.h5"
        scene = ts.static(ts.Probe(8.7, 0.0, 0.5), duration_s=seconds)
        peaks.append(
            _peak_bytes(lambda: simulate_to_file(spec, scene, path, rng=0, flaws=flaws))  # noqa: B023
        )
    assert peaks[1] < peaks[0] + 0.2e6, peaks
