"""Reading and writing recordings."""

from tactsense.io.recording import Recording, RecordingError, read_recording, write_recording

__all__ = ["Recording", "RecordingError", "read_recording", "write_recording"]
