"""Issue 31, found beyond its list: a recording made straight to MCAP kept no loss
counters (the HDF5 recorder stores /losses). The counters go into the metadata record
``tactsense.losses``, read with mcap's own reader, and ``import`` gives them back."""

import dataclasses

import numpy as np
from mcap.reader import make_reader
from typer.testing import CliRunner

import tactsense as ts
from tactsense.cli import app
from tactsense.io.recording import read_recording, write_recording
from tactsense.stream import LOSS_KINDS, Emulator, FaultRates

runner = CliRunner()


def _losses_record(path) -> dict[str, str]:
    with open(path, "rb") as stream:
        records = [m for m in make_reader(stream).iter_metadata() if m.name == "tactsense.losses"]
    assert len(records) == 1, [m.name for m in records]
    return dict(records[0].metadata)


def test_record_to_mcap_keeps_the_loss_counters(tmp_path):
    spec = ts.fearing1990_initial()
    rec = ts.simulate(spec, ts.probe_sweep(spec), rng=0)
    # drops and garbage on the line: sequence gaps and garbage runs to count
    emulator = Emulator.from_recording(
        rec, speed=0, faults=FaultRates(drop=0.1, garbage=0.1), rng=5
    )
    _, port = emulator.start_tcp()
    out = tmp_path / "live.mcap"
    try:
        result = runner.invoke(
            app, ["record", f"socket://127.0.0.1:{port}", "--frames", "100", "--out", str(out)]
        )
    finally:
        emulator.stop()
    assert result.exit_code == 0, result.output
    kept = _losses_record(out)
    assert set(kept) == set(LOSS_KINDS)
    assert int(kept["lost"]) > 0 and int(kept["garbage"]) > 0  # the faults were counted
    # the sequence numbers in the file agree with the 'lost' counter kept beside them
    with open(out, "rb") as stream:
        seqs = [m.sequence for _, _, m in make_reader(stream).iter_messages(["/tactile_states"])]
    steps = np.diff(np.asarray(seqs, dtype=np.int64))
    assert int(np.sum(steps - 1)) == int(kept["lost"])
    # and import gives them back with the frames
    back = tmp_path / "back.h5"
    imported = runner.invoke(app, ["import", str(out), "--out", str(back)])
    assert imported.exit_code == 0, imported.output
    assert read_recording(back).losses == {k: int(v) for k, v in kept.items()}


def test_export_and_import_keep_a_recordings_losses(tmp_path):
    spec = ts.fearing1990_initial()
    counts = {"lost": 7, "gaps": 2, "bad_check": 3, "truncated": 1, "garbage": 4,
              "garbage_bytes": 61, "timeouts": 1, "duplicates": 0}  # fmt: skip
    rec = dataclasses.replace(ts.simulate(spec, ts.probe_sweep(spec), rng=0), losses=counts)
    write_recording(tmp_path / "r.h5", rec)
    out = tmp_path / "r.mcap"
    exported = runner.invoke(app, ["export", str(tmp_path / "r.h5"), "--out", str(out)])
    assert exported.exit_code == 0, exported.output
    assert _losses_record(out) == {k: str(v) for k, v in counts.items()}
    imported = runner.invoke(app, ["import", str(out), "--out", str(tmp_path / "b.h5")])
    assert imported.exit_code == 0, imported.output
    assert read_recording(tmp_path / "b.h5").losses == counts
