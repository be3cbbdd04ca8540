"""Bad options of the wire formats (docs/devices.md): a marker that is not hex, a width
that is not 8 or 16, an unknown option or format, no sensor for a format that cannot
say which it is, a device of another shape. Each ends with exit status 2 and one line
naming what was wrong, no traceback, and nothing at the output name."""

import numpy as np
import pytest
from typer.testing import CliRunner

from tactsense.cli import app
from tactsense.sensor import load_sensor
from tactsense.stream import Emulator
from tactsense.stream.sources import parse_format

runner = CliRunner()


def _check(result, names: str) -> None:
    message = " ".join(result.output.split())  # rich wraps long lines
    assert result.exit_code == 2, message
    assert "Traceback" not in message
    assert names in message, message


LINE = "socket://127.0.0.1:9"  # never reached: the options are refused first

BAD_OPTIONS = [
    (f"record marker,start=ZZ:{LINE} --sensor pad16 --out OUT", "start='ZZ' is not a marker"),
    (f"record marker,start=:{LINE} --sensor pad16 --out OUT", "is not a marker of hex bytes"),
    (
        f"record marker,start=00112233445566778899:{LINE} --sensor pad16 --out OUT",
        "expected 1 to 8 bytes",
    ),
    (f"record marker,width=12:{LINE} --sensor pad16 --out OUT", "width='12' must be 8 or 16"),
    (f"live marker,order=middle:{LINE} --sensor pad16", "order='middle' must be little or big"),
    (f"record text,sep=pipe:{LINE} --sensor pad16 --out OUT", "sep='pipe' is not a separator"),
    (f"record text,header=-1:{LINE} --sensor pad16 --out OUT", "header="),
    (f"record text,colour=red:{LINE} --sensor pad16 --out OUT", "unknown option 'colour=red'"),
    (f"record justfloat,scale=0:{LINE} --sensor pad16 --out OUT", "scale='0' must be"),
    (f"record justfloat,tail=xyz:{LINE} --sensor pad16 --out OUT", "tail='xyz' is not a marker"),
    ("record text: --sensor pad16 --out OUT", "no line after the format"),
    (f"record text:{LINE} --out OUT", "give the sensor (--sensor"),
    (f"live justfloat:{LINE}", "give the sensor (--sensor"),
    ("emulate --format csv --port 0", "unknown wire format 'csv'"),
    ("emulate --format marker,width=7 --port 0", "width='7' must be 8 or 16"),
]


@pytest.mark.parametrize("line, names", BAD_OPTIONS, ids=[line for line, _ in BAD_OPTIONS])
def test_bad_format_options(tmp_path, line, names):
    out = tmp_path / "never_written.h5"
    result = runner.invoke(app, line.replace("OUT", str(out)).split())
    _check(result, names)
    assert not out.exists()


@pytest.mark.parametrize(
    "spec, names",
    [
        ("text", "the device prints lines of 256 values, but the sensor has 8x8 = 64"),
        # 16 bits: 8-bit samples of a 12-bit sensor are refused before the line opens
        ("marker,width=16", "sends 256 samples of 16 bits between markers, but the sensor has 8x8"),
        ("justfloat", "sends 256 floats between tails, but the sensor has 8x8 = 64"),
    ],
)
def test_a_device_of_another_shape(tmp_path, spec, names):
    """A 16x16 pad read as the 8x8 finger: named, not recorded as garbage forever."""
    pad = load_sensor("pad16")
    frames = np.random.default_rng(0).integers(0, 100, (50, *pad.shape))
    emulator = Emulator(pad, frames, speed=0, wire_format=parse_format(spec))
    _, port = emulator.start_tcp()
    out = tmp_path / "never_written.h5"
    try:
        result = runner.invoke(
            app,
            ["record", f"{spec}:socket://127.0.0.1:{port}", "--sensor", "initial", "-o",
             str(out), "--quiet"],
        )  # fmt: skip
    finally:
        emulator.stop()
    _check(result, names)
    assert not out.exists()


def test_a_silent_device_is_an_error(tmp_path):
    """A device that sends nothing in the format: an error after the stated wait."""
    pad = load_sensor("pad16")
    emulator = Emulator(pad, np.zeros((5, *pad.shape)), speed=0, wire_format=parse_format("text"))
    _, port = emulator.start_tcp()
    out = tmp_path / "never_written.h5"
    try:
        result = runner.invoke(
            app,
            ["record", f"marker,width=16:socket://127.0.0.1:{port}", "--sensor", "pad16", "-o",
             str(out), "--quiet"],
        )  # fmt: skip
    finally:
        emulator.stop()
    _check(result, "the line closed before any frame arrived; seen, garbage 1")
    assert not out.exists()
