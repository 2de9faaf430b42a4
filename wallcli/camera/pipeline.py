"""The decode as every analysis reads it: a camera pipeline's artefacts taken out, in one pass.

Repeated frames (a DVR's padding) are left out (:mod:`wallcli.camera.repeats`), burned-in
overlays masked (:mod:`wallcli.camera.overlay`) and an interlaced clip's fields brought to one
instant (:mod:`wallcli.camera.interlace`), in that order: a copy is no step of a clock, and a
recorder's text, which does not follow the wall's light, would read as fields at two instants
(its fill follows the light as the wall does). Each keeps a few frames at most; memory stays flat.
"""

from __future__ import annotations

from typing import Iterator

from wallcli.signal.blocks import one_opencv_thread
from wallcli.camera.interlace import InterlaceFilter
from wallcli.camera.overlay import OverlayFilter
from wallcli.camera.repeats import RepeatFilter


class CameraPipeline:
    """A reader whose :meth:`frames` are the cleaned frames; everything else is the reader's.

    ``check`` (a :class:`wallcli.view.check.ViewCheck`, or several) is told the overlay boxes
    masked, for the ``view`` it reports and the ROI it avoids. ``decoded`` counts the file's frames."""

    def __init__(self, reader, check=None) -> None:
        self.reader = reader
        self.repeats = RepeatFilter(reader)
        self.overlay = OverlayFilter(self.repeats, check)
        self.interlace = InterlaceFilter(self.overlay)

    def __getattr__(self, name: str):
        return getattr(self.reader, name)

    @property
    def decoded(self) -> int:
        return self.repeats.decoded

    @property
    def last_time(self) -> float:
        return self.repeats.last_time

    def frames(self) -> Iterator:
        # One OpenCV thread for the whole decode, not toggled per call: a toggle after the pool
        # has worked rebuilds it (0.3-0.7 ms, 4 a frame; 2.4 s of a 900-frame 1080p count).
        with one_opencv_thread():
            yield from self.interlace.frames()

    def corrections(self) -> list[dict]:
        """The ``corrections`` entries (docs/contract.md) of what was found and taken out."""
        return [c for c in (self.repeats.correction(), self.interlace.correction()) if c]
