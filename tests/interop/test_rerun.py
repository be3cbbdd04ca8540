"""Rerun: written by tactsense, read back with Rerun's own reader (rerun.chunk.RrdReader),
compared frame by frame with the recording and its estimates."""

import numpy as np
import pytest
from typer.testing import CliRunner

import tactsense as ts
from tactsense.cli import app
from tactsense.estimate import Flag
from tactsense.estimate.finger.deflection import deflection_from_counts
from tactsense.io.recording import write_recording
from tactsense.physics.contact import newtons_to_grams

runner = CliRunner()


def _columns(path):
    from rerun.chunk import RrdReader

    found = {}
    for chunk in RrdReader(str(path)).stream().to_chunks():
        batch = chunk.to_record_batch()
        names = batch.schema.names
        if "time" not in names:
            continue
        times = [t.total_seconds() for t in batch.column("time").to_pylist()]
        for name in names:
            if ":" in name:
                key = (str(chunk.entity_path), name)
                found.setdefault(key, []).extend(
                    zip(times, batch.column(name).to_pylist(), strict=True)
                )
    return {key: sorted(rows, key=lambda row: row[0]) for key, rows in found.items()}


def test_export_heat_map_contact_and_force(tmp_path, initial):
    rec = ts.simulate(initial, ts.probe_sweep(initial, along="axial", dwell_s=0.3), rng=8)
    path, out = tmp_path / "rec.h5", tmp_path / "rec.rrd"
    write_recording(path, rec)
    result = runner.invoke(app, ["export", str(path), "--out", str(out)])
    assert result.exit_code == 0, result.output
    columns = _columns(out)
    baseline = ts.baseline_from(rec.frames, 5)
    deflection, _ = deflection_from_counts(rec.frames, baseline, rec.sensor)
    est = ts.locate(rec.frames, rec.sensor, baseline=baseline)
    touching = ((est.flags & int(Flag.NO_CONTACT)) == 0) & np.isfinite(est.force_n)

    tensors = columns[("/finger/deflection_values", "Tensor:data")]
    assert len(tensors) == len(rec)
    for k, (t, tensor) in enumerate(tensors):
        assert t == pytest.approx(rec.time_s[k], abs=1e-9)
        assert tensor[0]["shape"] == [8, 8]
        image = np.asarray(tensor[0]["buffer"], dtype=np.float32).reshape(8, 8)
        np.testing.assert_array_equal(image, deflection[k].T.astype(np.float32))
    # one colour scale for the whole file: the recording's lowest (or 0) to highest deflection
    low, high = min(0.0, float(deflection.min())), float(deflection.max())
    key = ("/finger/deflection_values", "Tensor:value_range")
    ranges = {tuple(r[1][0]) for r in columns[key]}
    assert len(ranges) == 1
    assert next(iter(ranges)) == pytest.approx((low, high), rel=1e-12)
    images = columns[("/finger/deflection", "Image:buffer")]
    assert len(images) == len(rec)
    assert not any(name.startswith("DepthImage") for _, name in columns)  # no metres

    forces = columns[("/finger/force_g", "Scalars:scalars")]
    expected = np.where(touching, newtons_to_grams(np.nan_to_num(est.force_n)), 0.0)
    np.testing.assert_allclose([row[1][0] for row in forces], expected, rtol=1e-12)

    points = columns[("/finger/deflection/contact", "Points2D:positions")]
    assert len(points) == int(touching.sum())
    index = {round(t, 9): i for i, t in enumerate(rec.time_s)}
    for t, value in points:
        i = index[round(t, 9)]
        assert touching[i]
        np.testing.assert_allclose(value[0], [est.row[i] + 0.5, est.col[i] + 0.5], atol=1e-5)


def _properties(path):
    """The recording ids of the stores in the file (Rerun's own reader), and the
    ``tactsense`` recording properties."""
    from rerun.chunk import RrdReader

    reader = RrdReader(str(path))
    ids = [store.recording_id for store in reader.recordings()]
    props = {}
    for chunk in reader.stream().to_chunks():
        if str(chunk.entity_path) == "/__properties/tactsense":
            row = chunk.to_record_batch().to_pylist()[0]
            props.update({k: v for k, v in row.items() if not k.startswith("rerun.")})
    return ids, props


def test_two_exports_of_same_named_recordings_get_different_ids(tmp_path, initial):
    """Recording ids are unique per export (two rec.h5 would merge under the file stem)."""
    from tactsense.interop.rerun import export_rerun

    rec = ts.simulate(initial, ts.probe_sweep(initial, along="axial", dwell_s=0.3), rng=8)
    ids = []
    for folder in ("a", "b"):
        (tmp_path / folder).mkdir()
        path = tmp_path / folder / "rec.h5"
        write_recording(path, rec)
        result = export_rerun(path, tmp_path / folder / "rec.rrd")
        ids.append(result["recording_id"])
        stores, props = _properties(tmp_path / folder / "rec.rrd")
        assert stores == [result["recording_id"]]
        assert props["recording_id"] == [result["recording_id"]]  # also in the properties
        assert "fraction of the undeflected reading" in props["deflection_units"][0]
        assert props["force_units"] == ["g"]
    assert ids[0] != ids[1] and "rec" not in ids
