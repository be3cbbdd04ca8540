"""``tactsense info`` on taxels of several components (r8-triwire): how many, their
names, and each component's finite range, gathered chunk by chunk as ``info`` streams
the recording (memory stays flat)."""

from __future__ import annotations

from collections.abc import Iterable, Iterator

import numpy as np


class ComponentRanges:
    """The finite range of each component of a recording's frames; nothing for a
    sensor of one component per taxel."""

    def __init__(self, spec):
        self.components = int(spec.components)
        names = tuple(spec.component_names)
        padded = names + tuple(f"c{k}" for k in range(self.components))
        self.names = padded[: self.components]
        self.low = np.full(self.components, np.inf)
        self.high = np.full(self.components, -np.inf)

    def add(self, frames: np.ndarray) -> None:
        """Take the frames ``(T, rows, cols, components)`` of one chunk into account."""
        if self.components == 1 or not np.size(frames):
            return
        values = np.asarray(frames).reshape(-1, self.components)
        finite = np.isfinite(values)
        self.low = np.minimum(self.low, np.where(finite, values, np.inf).min(axis=0))
        self.high = np.maximum(self.high, np.where(finite, values, -np.inf).max(axis=0))

    def watch(self, chunks: Iterable[tuple]) -> Iterator[tuple]:
        """The chunks of :meth:`RecordingReader.chunks` as they are, each taken into
        account on the way (its second item: the frames)."""
        for chunk in chunks:
            self.add(chunk[1])
            yield chunk

    def text(self) -> str:
        """``x 29658 .. 33012, y ..., z ...``; empty for one component or none finite."""
        if self.components == 1 or not np.isfinite(self.low).any():
            return ""
        return ", ".join(
            f"{name} {lo:g} .. {hi:g}" if np.isfinite(lo) else f"{name} none finite"
            for name, lo, hi in zip(self.names, self.low, self.high, strict=True)
        )

    def add_rows(self, table) -> None:
        """The rows ``components`` and ``counts by component`` of ``info``'s table."""
        if self.components == 1:
            return
        names = ", ".join(self.names)
        table.add_row("components", f"{self.components} per taxel ({names}), the last axis")
        if self.text():
            table.add_row("counts by component", self.text())
