"""What an input is (a URL, a pipe, a real video stream) and what to say when it cannot be opened."""

from __future__ import annotations

import re

from wallcli.errors import WallcliError

STDIN_MP4 = ("-: an MP4 cannot be streamed on stdin (its index is at the end of the file, where a pipe "
             "cannot seek); give its path, or stream MPEG-TS, Matroska, NUT or Y4M "
             "(ffmpeg -i clip.mp4 -c copy -f mpegts -)")

# Lossy legacy codecs that ffmpeg writes by default to a pipe (NUT and AVI: MPEG-4 Part 2; MPEG-TS:
# MPEG-2) or on a plain -c mjpeg, and that no current camera streams: on stdin they mean the
# camera's stream was re-encoded (`-f nut -` without `-c copy`), which changes the faint wall
# signal and so the answers (examples/walking.mp4 through `-f nut` answers otherwise than the file)
REENCODED = {"mpeg4": "MPEG-4 Part 2", "msmpeg4v1": "MS MPEG-4 v1", "msmpeg4v2": "MS MPEG-4 v2",
             "msmpeg4": "MS MPEG-4 v3", "mjpeg": "Motion JPEG", "mpeg1video": "MPEG-1", "mpeg2video": "MPEG-2"}


def _real_video(stream) -> bool:
    """A stream of moving pictures that FFmpeg can decode, not a cover picture or a thumbnail track."""
    d = getattr(stream, "disposition", None)
    try:
        still = bool(d & (d.__class__.attached_pic | d.__class__.timed_thumbnails | d.__class__.still_image))
    except (AttributeError, TypeError):
        still = False
    return not still and stream.codec_context is not None


class NotAVideo(WallcliError):
    """FFmpeg opened the input but found no video in it (a text file, a CSV, a cut header): a
    command that reads something else too (``wallcli report``) can say what it accepts.
    ``detail``: what was found, without the input's name ("FFmpeg: Invalid data found ...")."""

    def __init__(self, message: str, detail: str = ""):  # a default: unpickled (a scan worker) from args
        super().__init__(message)
        self.detail = detail or message


def _describe_open_error(source: str, exc: Exception) -> WallcliError:
    text = str(exc).replace(": '<none>'", "")  # (PyAV's name for a stream it reads from Python)
    if isinstance(exc, FileNotFoundError) or "No such file" in text:
        return WallcliError(f"no such file: {source}")
    if "Permission denied" in text:
        return WallcliError(f"cannot read {source}: permission denied")
    # FFmpeg's own words, without PyAV's "[Errno 1094995529] ...: 'path'" around them (an AVERROR
    # tag read as a number, and the path the line already names)
    why = getattr(exc, "strerror", None) or text.strip() or type(exc).__name__
    return NotAVideo(f"{source} is not a readable video (FFmpeg: {why})", f"FFmpeg: {why}")


def _is_url(source: str) -> bool:
    return re.match(r"^[a-zA-Z][a-zA-Z0-9+.-]*://", source) is not None
