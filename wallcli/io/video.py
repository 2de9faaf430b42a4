"""One streaming video reader on PyAV: files, URLs, stdin ('-') and cameras.

Frames come out as their decoded planes (Y, U, V at their native bit depth), never as rounded
8-bit RGB: the wall signal is a fraction of a code value, and converting to rgb24 first would
quantise it away. Block averages are taken on the planes and only then converted to RGB (the
conversion is affine, so the mean commutes with it).

Decoding runs in a background thread feeding a small queue (PyAV releases the GIL while it
decodes), so decode and the per-frame arithmetic overlap on two cores; memory stays bounded by
the queue, whatever the video's length.
"""

from __future__ import annotations

import math
import os
import queue
import re
import threading
import warnings
from contextvars import ContextVar
from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path
from typing import Iterator

import numpy as np

from wallcli.errors import WallcliError
# the planes a frame decodes to (importable from here too, as before the split)
from wallcli.io.planes import Planes, frame_planes, quarter_turns, rotate_planes  # noqa: F401

STDIN_MP4 = ("-: an MP4 cannot be streamed on stdin (its index is at the end of the file, where a pipe "
             "cannot seek); give its path, or stream MPEG-TS, Matroska, NUT or Y4M "
             "(ffmpeg -i clip.mp4 -c copy -f mpegts -)")

# The video stream to read (its index in the file, as ffprobe numbers them), for commands given
# --stream N (cli.common.use_stream); None: the first real video stream
STREAM: ContextVar[int | None] = ContextVar("wallcli_stream", default=None)

# How long a byte stream (stdin, a FIFO, <(...)) may send nothing before the read fails saying so,
# for commands given --stall-timeout (cli.common.use_stream); None: wait for ever (a live feed)
DEFAULT_STALL = 30.0
STALL: ContextVar[float | None] = ContextVar("wallcli_stall", default=DEFAULT_STALL)
_POLL = 0.2  # s: how often a wait on a stream looks at its stop flag (a signal ends it within this)
# --follow on a regular file: read it as it grows, until it has not grown for this many seconds
# (None: read what is there, as any file)
FOLLOW_IDLE: ContextVar[float | None] = ContextVar("wallcli_follow_idle", default=None)
FLUSH_FACTOR = 3.0  # a followed file ends after this many of its longest waits for growth, if longer


_QUEUE_SIZE = 8

# The frame rates wallcli reads. The models see 8.5 s windows resampled to 30 fps, trained on 15-60 fps
# videos, and the SNR estimator (paper suppl. 3.2) takes what lasts from one frame to the next as
# signal: far below 10 fps a person moves across the wall between two frames and both would be
# answering about interpolated samples (a 0.5 fps file gave eight windows and 32 dB, snr -99 dB);
# far above 240 fps, the timestamps of slow-motion files are rarely the capture's.
MIN_FPS, MAX_FPS = 10.0, 240.0
# The frame intervals whose median the rate check reads (the rest of a file is checked by then), and
# how far the frames' measured rate may stray from the container's before it is the one reported
RATE_PROBE = 16
RATE_TOLERANCE = 0.02


def check_rate(fps: float, source: str) -> None:
    """Refuse a frame rate outside MIN_FPS-MAX_FPS: one line, the same for every command."""
    if not (MIN_FPS <= float(fps) <= MAX_FPS):
        raise WallcliError(f"{source}: {float(fps):.3g} fps; wallcli reads videos of {MIN_FPS:g} to {MAX_FPS:g} fps "
                           "(the models' windows and the SNR estimator assume frames a fraction of a second apart)")


@dataclass
class VideoInfo:
    source: str
    width: int
    height: int
    fps: Fraction
    frame_count: int | None
    pix_fmt: str
    duration: float | None
    codec: str = ""  # FFmpeg's decoder name, e.g. 'h264' (for reports of the evidence)
    container: str = ""  # FFmpeg's demuxer name, e.g. 'mov,mp4,m4a,3gp,3g2,mj2'
    # where fps came from: 'container', 'codec' (its headers) or 'assumed'; a plot's meta also
    # 'timestamps' (the frames' own rate, where it contradicts the container's)
    fps_source: str = "container"


@dataclass
class Frame:
    index: int
    time: float
    planes: Planes
    _keep: object = field(default=None, repr=False)  # the av.VideoFrame whose buffers the planes view
    gap: float = 0.0  # seconds since the frame before, when the timestamps jump there (frames lost): 0 otherwise


# A jump of the timestamps over GAP_FACTOR typical frame intervals, and over GAP_MIN seconds, is frames
# lost (corruption, a dropped stretch of a stream), not a variable frame rate's slower frame (phones:
# up to about 2x; a few frames' pause is interpolated over like any resampling)
GAP_FACTOR = 5.0
GAP_MIN = 0.25
GAP_HISTORY = 16  # recent intervals whose median is the typical one

# FFmpeg's demuxers of bare elementary streams: no timestamps, and an average_rate that is only
# the demuxer's -framerate default (25), whatever the frames are; the codec's headers (H.264's
# VUI timing, MPEG-2's sequence header) are what knows the rate
RAW_DEMUXERS = frozenset({"h264", "hevc", "vvc", "m4v", "mpegvideo", "cavsvideo", "avs2", "avs3", "vc1", "dirac",
                          "mjpeg", "dnxhd"})
RAW_DEFAULT_FPS = 25  # what FFmpeg assumes for such a stream that states no rate

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


class _Stopped(Exception):
    """The read was stopped (the reader closed, or a signal in the main thread): an Exception, so
    that PyAV hands it back where FFmpeg returns instead of dropping it."""


def _front_to_back(path: str) -> bool:
    """Whether a file can be read as a stream, front to back (what reading it as it grows needs):
    not an MP4/MOV whose index (moov) comes after its media (mdat), as most recorders write it
    when they finish; a fragmented or 'faststart' MP4 and MPEG-TS, MKV, raw streams can."""
    import struct

    try:
        with open(path, "rb") as fh:
            head = fh.read(8)
            if len(head) < 8 or head[4:8] != b"ftyp":
                return True
            fh.seek(0)
            for _ in range(64):
                box = fh.read(8)
                if len(box) < 8:
                    # its header is still being written (nothing after 'ftyp' yet): what follows
                    # will tell, and a reader that waits for it loses nothing
                    return True
                size, kind = struct.unpack(">I4s", box)
                if kind in (b"moov", b"moof"):
                    return True
                if kind == b"mdat":
                    return False
                if size == 1:
                    size = struct.unpack(">Q", fh.read(8))[0] - 8
                elif size == 0:
                    return False
                fh.seek(size - 8, os.SEEK_CUR)
    except (OSError, struct.error):
        return True
    return False


class StreamInput:
    """A byte stream (stdin, a FIFO) read by a thread of ours and handed to FFmpeg as a Python file.

    FFmpeg's own read() of a pipe blocks in C, where neither Ctrl-C, SIGTERM nor the decoder's stop
    reach it (a stalled writer held wallcli for as long as it stalled); here every wait is in
    Python, in steps of _POLL, and fails with one line after ``stall`` seconds without data. Memory:
    at most 64 chunks of 64 KiB queued."""

    def __init__(self, source: str, path: str | None, stall: float | None, idle: float | None = None) -> None:
        self.source, self.stall = source, stall
        self.idle = idle  # a growing file: at its end, wait this long for more before calling it the end
        self._longest = 0.0  # the longest wait at its end before it grew: how slowly its recorder flushes
        self.interrupted = False  # a signal arrived while FFmpeg read in the main thread
        self._q: queue.Queue = queue.Queue(maxsize=64)
        self._stop = threading.Event()
        self._buf = b""
        self._done = False  # EOF given, or the read failed once (FFmpeg may ask again: say EOF)
        threading.Thread(target=self._pump, args=(path,), daemon=True, name="wallcli-input").start()

    def _pump(self, path: str | None) -> None:
        # (opening a FIFO blocks until its writer opens it: here, not in the main thread). The
        # thread may stay in os.read when the command ends: a daemon, holding nothing of FFmpeg's.
        try:
            fd = os.dup(0) if path is None else os.open(path, os.O_RDONLY)
        except OSError as exc:
            return self._put(exc)
        try:
            while not self._stop.is_set():
                chunk = os.read(fd, 1 << 16)
                if not chunk and self.idle is not None and self._grows(fd):
                    continue
                self._put(chunk)
                if not chunk:
                    break
        except OSError as exc:
            self._put(exc)
        finally:
            os.close(fd)

    def _grows(self, fd: int) -> bool:
        """At the end of a file being written: whether it grows within ``idle`` seconds, or within
        FLUSH_FACTOR times the longest pause between its growths so far (a recorder that flushes
        every 5 s outlasted a 5 s --idle-timeout and was taken for finished)."""
        import time

        end, waited = os.lseek(fd, 0, os.SEEK_CUR), 0.0
        while not self._stop.is_set() and waited < max(self.idle, FLUSH_FACTOR * self._longest):
            if os.fstat(fd).st_size > end:
                # the wait is a lower bound of the recorder's pause (not the time we spent reading)
                self._longest = max(self._longest, waited)
                return True
            time.sleep(_POLL)
            waited += _POLL
        return False

    def _put(self, item) -> None:
        while not self._stop.is_set():
            try:
                return self._q.put(item, timeout=_POLL)
            except queue.Full:
                pass

    def read(self, n: int) -> bytes:
        try:
            return self._read(int(n))
        except KeyboardInterrupt:  # the signal handler's raise, inside FFmpeg's call of read()
            self.interrupted = True
            self._done = True
            raise _Stopped("interrupted") from None
        except BaseException:
            self._done = True
            raise

    def _read(self, n: int) -> bytes:
        if not self._buf:
            if self._done:
                return b""
            import time

            waited = 0.0
            while True:
                if self._stop.is_set():
                    raise _Stopped("stopped")
                t = time.monotonic()
                try:
                    item = self._q.get(timeout=_POLL)
                    break
                except queue.Empty:
                    waited += time.monotonic() - t
                    if self.stall is not None and waited >= self.stall:
                        raise WallcliError(f"{self.source}: no data for {self.stall:g} s (its writer stalled)",
                                           hint="--stall-timeout SECONDS waits longer; 0, for ever")
            if isinstance(item, OSError):
                raise WallcliError(f"cannot read {self.source}: {item.strerror or item}")
            if not item:
                self._done = True
                return b""
            self._buf = item
        out, self._buf = self._buf[:n], self._buf[n:]
        return out

    def close(self) -> None:
        self._stop.set()


def _byte_stream(source: str) -> bool:
    """A path that is a pipe, socket or character device (not a camera): read as a stream."""
    import stat

    if source.startswith("/dev/video"):
        return False
    try:
        mode = os.stat(source).st_mode
    except OSError:
        return False
    return stat.S_ISFIFO(mode) or stat.S_ISSOCK(mode) or stat.S_ISCHR(mode)


class VideoReader:
    """Open with :func:`open_video`; iterate :meth:`frames` once (decode once, stream)."""

    def __init__(self, source: str, *, threads: int = 0, input_format: str | None = None,
                 stream_index: int | None = None):
        import av

        self.source = source
        self.warnings: list[str] = []
        options: dict[str, str] = {}
        target = source
        fmt = input_format
        self._input = None
        self.following = (FOLLOW_IDLE.get() is not None and source != "-" and os.path.isfile(source)
                          and _front_to_back(source))
        if source == "-" or _byte_stream(source):
            target = self._input = StreamInput(source, None if source == "-" else source, STALL.get())
        elif self.following:  # a recording still being written: read as it grows (see StreamInput)
            target = self._input = StreamInput(source, source, None, idle=FOLLOW_IDLE.get())
        elif _is_url(source):
            if source.startswith("rtsp://"):
                options["rtsp_transport"] = "tcp"
            options.setdefault("rw_timeout", "15000000")
        elif source.startswith("/dev/video"):
            fmt = fmt or "v4l2"
        else:
            p = Path(source)
            if not p.exists():
                if p.is_symlink():  # exists() is False for a loop as for a dangling link: say which
                    raise WallcliError(f"{source} is a symbolic link to nothing (a loop, or its target is gone)")
                raise WallcliError(f"no such file: {source}")
            if p.is_dir():
                raise WallcliError(f"{source} is a folder, not a video")
            # only a regular file's size means anything: a FIFO, <(...), /dev/stdin or a device
            # reports 0 and is read as a stream
            if p.is_file() and p.stat().st_size == 0:
                raise WallcliError(f"{source} is empty (0 bytes)")
        try:
            self._container = av.open(target, mode="r", format=fmt, options=options, timeout=30.0)
        except (av.error.FFmpegError, OSError, ValueError, _Stopped) as exc:
            if self._input is not None:
                self._input.close()
                if self._input.interrupted:
                    from wallcli.errors import Interrupted

                    raise Interrupted from None
            raise _describe_open_error(source, exc) from None
        except BaseException:
            if self._input is not None:
                self._input.close()
            raise
        if not self._container.streams.video:
            self._container.close()
            raise NotAVideo(f"{source} has no video stream", "it has no video stream")
        try:
            stream = self._pick_stream(source, STREAM.get() if stream_index is None else stream_index)
        except WallcliError:
            self._container.close()
            raise
        stream.thread_type = "AUTO"  # frame + slice threads: most of our time is decode
        stream.codec_context.thread_count = int(threads)
        self._stream = stream
        fps_source = "container"
        container_name = str(self._container.format.name or "")
        raw = container_name in RAW_DEMUXERS
        rate = None if raw else stream.average_rate
        if raw:
            stated = stream.codec_context.framerate
            if stated and stated > 0:
                rate, fps_source = stated, "codec"
                self.warnings.append(f"{source}: a bare {container_name} stream has no timestamps; read at "
                                     f"{float(stated):.4g} fps, the rate its codec headers state")
            else:
                rate, fps_source = Fraction(RAW_DEFAULT_FPS), "assumed"
                self._warn(f"{source}: a bare {container_name} stream states no frame rate; assuming "
                           f"{RAW_DEFAULT_FPS} fps (FFmpeg's default): times and rates are wrong if it is not")
        rate = rate or stream.guessed_rate or stream.base_rate
        if not rate or rate <= 0:
            rate, fps_source = Fraction(30), "assumed"
            self.warnings.append(f"{source}: no frame rate in the stream; assuming 30 fps")
        fps = Fraction(rate).limit_denominator(1001)
        try:
            # the measured or stated rate only: a container that gives none leaves FFmpeg guessing
            # from its time base (Matroska's 1000), which says nothing of the frames
            if stream.average_rate or fps_source == "codec":
                check_rate(fps, source)
        except WallcliError:
            self._container.close()
            raise
        count = int(stream.frames or 0) or None
        self._declared_frames = count  # exact where the container says (mp4); estimates are not
        duration = None
        if stream.duration and stream.time_base:
            duration = float(stream.duration * stream.time_base)
        elif self._container.duration:
            duration = self._container.duration / 1_000_000
        if count is None and duration:
            count = int(round(duration * float(fps))) or None
        cc = stream.codec_context
        self.info = VideoInfo(
            source=source,
            width=int(cc.width or stream.width or 0),
            height=int(cc.height or stream.height or 0),
            fps=fps,
            frame_count=count,
            pix_fmt=str(cc.pix_fmt or ""),
            duration=duration,
            codec=str(cc.name or ""),
            container=container_name,
            fps_source=fps_source,
        )
        if self._input is not None and not self.following and self.info.codec in REENCODED:
            self._warn(f"{source}: the stream is {REENCODED[self.info.codec]} ({self.info.codec}), a lossy codec "
                       "ffmpeg re-encodes to when not told to copy (e.g. `-f nut -`); a re-encode changes the "
                       "wall's faint signal and the answers: copy the stream instead "
                       "(ffmpeg -i SOURCE -c copy -f nut -)")
        self.rotation = 0  # quarter turns (np.rot90's k) applied to every frame: its display matrix
        self._rotation_noted = False
        self._peek_rotation(target, fmt, options)
        self._used = False
        self._worker = None  # (thread, queue, stop event) while frames() runs
        self.gaps: list[tuple[float, float]] = []  # (time of the frame before, time of the frame after) per jump
        self._steady = [0, 0.0]  # frame intervals that are no gap: how many, their sum in seconds

    @property
    def measured_fps(self) -> float | None:
        """The frames' own rate so far: intervals counted, gaps (frames lost) not; None before two frames."""
        n, total = self._steady
        return n / total if n and total > 0 else None

    @property
    def fps(self) -> float:
        """The rate to report once the frames are read: the container's, unless the timestamps say
        otherwise by more than RATE_TOLERANCE (a stream labelled 30 fps whose frames are 0.1 s
        apart, a 30 fps GIF whose 3-3-4 centisecond delays are read as 33.3 fps)."""
        got, said = self.measured_fps, float(self.info.fps)
        return got if got is not None and abs(got - said) > RATE_TOLERANCE * said else said

    def _check_intervals(self, intervals: list[float]) -> None:
        """Refuse (check_rate) frames whose median spacing is outside the rates wallcli reads,
        whatever the container says (one frame an hour in a file labelled 30 fps); one tick of
        the time base either way is the timestamps' rounding (240 fps in milliseconds: 4 or 5)."""
        if len(intervals) < 2:
            return
        m = float(np.median(intervals))
        tick = float(self._stream.time_base or 0)
        fastest = 1.0 / max(m - tick, 1e-12)
        slowest = 1.0 / (m + tick) if m + tick > 0 else math.inf
        if fastest < MIN_FPS or slowest > MAX_FPS:
            check_rate(1.0 / m if m > 0 else math.inf, self.source)

    def _pick_stream(self, source: str, index: int | None):
        """The video stream to read: ``index`` (--stream N) or the first real one; a file with
        several says which was taken."""
        videos = list(self._container.streams.video)
        if index is not None:
            chosen = [s for s in videos if s.index == index]
            if not chosen:
                names = ", ".join(str(s.index) for s in videos)
                raise WallcliError(f"{source} has no video stream {index} (its video streams: {names})")
            stream = chosen[0]
        else:
            real = [s for s in videos if _real_video(s)]
            stream = real[0] if real else videos[0]
            if len(videos) > 1:
                self.warnings.append(f"{source} has {len(videos)} video streams; reading stream {stream.index} "
                                     f"({stream.codec_context.name if stream.codec_context else '?'}, "
                                     f"{stream.codec_context.width if stream.codec_context else '?'}x"
                                     f"{stream.codec_context.height if stream.codec_context else '?'}); "
                                     "--stream N reads another")
                warnings.warn(self.warnings[-1], VideoWarning, stacklevel=3)
        if stream.codec_context is None:  # a codec FFmpeg has no decoder for (or a damaged header naming one)
            raise WallcliError(f"{source}: FFmpeg cannot decode its video codec")
        return stream

    def _peek_rotation(self, target: str, fmt, options) -> None:
        """A file's display rotation (its first frame's display matrix), known before the frames
        are read so that the announced size is the size shown. Streams and URLs are not read twice:
        their frames are turned as they come, and the size is the decoded frame's (as everywhere)."""
        if target != self.source or _is_url(self.source) or not os.path.isfile(self.source):
            return  # (a pipe or a device read twice would lose what the first read took)
        import av

        try:
            with av.open(target, mode="r", format=fmt, options=options, timeout=30.0) as c:
                s = c.streams[self._stream.index]
                for frame in c.decode(s):
                    k = quarter_turns(frame.rotation)
                    self.rotation = k or 0
                    if k and k % 2:
                        self.info.width, self.info.height = self.info.height, self.info.width
                    break
        except (av.error.FFmpegError, OSError, ValueError, IndexError):
            pass  # the real read reports what is wrong

    def _turn(self, frame, planes: Planes) -> Planes:
        k = quarter_turns(getattr(frame, "rotation", 0))
        if k is None:
            if not self._rotation_noted:
                self._rotation_noted = True
                self._warn(f"{self.source}: a display rotation of {-float(frame.rotation):g} degrees is not applied "
                           "(only quarter turns are); frames are read as stored")
            return planes
        if k and not self._rotation_noted:
            self._rotation_noted = True
            self.warnings.append(f"{self.source}: display rotation of {(-90 * k) % 360} degrees applied")
        return rotate_planes(planes, k)

    # -- decoding -------------------------------------------------------------------------------
    def _decode_into(self, q: "queue.Queue", stop: threading.Event) -> None:
        import av

        corrupt = 0
        try:
            for packet in self._container.demux(self._stream):
                if stop.is_set():
                    break
                try:
                    decoded = packet.decode()
                except av.error.InvalidDataError:
                    corrupt += 1
                    continue
                for frame in decoded:
                    if frame.is_corrupt:
                        corrupt += 1
                    q.put(("frame", frame))
                    if stop.is_set():
                        break
        except (av.error.EOFError, _Stopped):
            pass
        except (av.error.FFmpegError, OSError) as exc:
            q.put(("damage", str(exc).strip() or type(exc).__name__))
        except BaseException as exc:  # noqa: BLE001 - handed to the consumer thread
            q.put(("error", exc))
        finally:
            q.put(("end", corrupt))

    def frames(self) -> Iterator[Frame]:
        if self._used:
            raise RuntimeError("a VideoReader is read once (decode once); open the video again")
        self._used = True
        q: queue.Queue = queue.Queue(maxsize=_QUEUE_SIZE)
        stop = threading.Event()
        worker = threading.Thread(target=self._decode_into, args=(q, stop), daemon=True, name="wallcli-decode")
        self._worker = (worker, q, stop)
        worker.start()
        index = 0
        first_pts = None
        last_time = -np.inf
        tb = self._stream.time_base
        fps = float(self.info.fps)
        from collections import deque

        recent: deque = deque(maxlen=GAP_HISTORY)
        self.gaps = []
        self._steady = [0, 0.0]
        first_intervals: list[float] | None = []  # the first RATE_PROBE, then None (checked)
        size = None  # (width, height) of the first frame: every analysis holds per-pixel state of that size
        try:
            while True:
                kind, item = q.get()
                if kind == "frame":
                    frame = item
                    if frame.pts is not None and tb is not None:
                        if first_pts is None:
                            first_pts = frame.pts
                        t = float((frame.pts - first_pts) * tb)
                    else:
                        t = index / fps
                    if t <= last_time:
                        # Duplicate or out-of-order timestamps (broken muxers): keep time monotonic.
                        t = last_time + 1.0 / fps
                    gap = 0.0
                    if index:
                        dt = t - last_time
                        typical = float(np.median(recent)) if len(recent) >= 4 else 1.0 / fps
                        if dt > GAP_FACTOR * typical and dt > max(GAP_FACTOR / fps, GAP_MIN):
                            gap = dt
                            self.gaps.append((round(last_time, 4), round(t, 4)))
                        else:
                            recent.append(dt)
                            self._steady[0] += 1
                            self._steady[1] += dt
                        if first_intervals is not None:
                            first_intervals.append(dt)
                            if len(first_intervals) >= RATE_PROBE:
                                self._check_intervals(first_intervals)
                                first_intervals = None
                    last_time = t
                    planes = self._turn(frame, frame_planes(frame))
                    if size is None:
                        size = (planes.width, planes.height)
                    elif (planes.width, planes.height) != size:
                        raise self._size_changed(index, t, size, (planes.width, planes.height))
                    yield Frame(index, t, planes, frame, gap)
                    index += 1
                elif kind == "damage":
                    if index == 0 and self._mp4_on_a_pipe():
                        raise WallcliError(STDIN_MP4)
                    self._warn(f"{self.source}: the stream is damaged after frame {index} ({item}); "
                               "using the frames before the damage")
                elif kind == "error":
                    raise item
                elif kind == "stopped":  # interrupted from another thread (interrupt)
                    return
                else:
                    if item:
                        self._warn(f"{self.source}: skipped {item} corrupt packet(s)/frame(s)")
                    if self.gaps:
                        shown = ", ".join(f"{b - a:.2f} s after {a:.2f} s" for a, b in self.gaps[:3])
                        more = f" and {len(self.gaps) - 3} more" if len(self.gaps) > 3 else ""
                        self._warn(f"{self.source}: frames missing (the timestamps jump): {shown}{more}; "
                                   "what spans a gap is not analysed as continuous (view: 'frame gap')")
                    if first_intervals is not None:
                        self._check_intervals(first_intervals)
                    self._check_complete(index, last_time)
                    break
        finally:
            self._stop_worker()
        if index == 0:
            raise WallcliError(f"{self.source}: no frames could be decoded")

    def _size_changed(self, index: int, t: float, old: tuple[int, int], new: tuple[int, int]) -> WallcliError:
        """One line for every command: the block grids, plots and frames written so far all have the
        first size, and no analysis spans two views of a wall."""
        return WallcliError(f"{self.source}: the frame size changes from {old[0]}x{old[1]} to {new[0]}x{new[1]} at "
                            f"frame {index} ({t:.2f} s); wallcli analyses a video of one frame size",
                            hint=f"cut it there and analyse each part, e.g. ffmpeg -i IN -t {t:.2f} -c copy part1.ts")

    def _mp4_on_a_pipe(self) -> bool:
        """An MP4 (or MOV) read from stdin: its index usually sits at the end of the file, where a
        pipe cannot seek, so FFmpeg reports damage at the first frame (one written with
        '-movflags +faststart' streams)."""
        return self.source == "-" and "mp4" in self.info.container.split(",")

    def _check_complete(self, decoded: int, last_time: float) -> None:
        """Warn when the file promised more frames or more time than it held (truncation)."""
        if not decoded or self.source == "-" or _is_url(self.source) or self.following:
            return  # (a followed file's header was written before its end)
        expected = self._declared_frames
        duration = self.info.duration
        if expected and decoded < 0.9 * expected - 1:
            self._warn(f"{self.source}: decoded {decoded} of {expected} frames; the file looks truncated")
        elif duration and last_time + 2.0 / float(self.info.fps) < 0.9 * duration:
            self._warn(f"{self.source}: frames end at {last_time:.2f} s of {duration:.2f} s; "
                       "the file looks truncated")

    def _warn(self, message: str) -> None:
        self.warnings.append(message)
        warnings.warn(message, VideoWarning, stacklevel=2)

    def _stop_worker(self) -> None:
        """Stop the decoder thread and wait for it. A consumer that raises inside its ``for frame``
        loop leaves the frames() generator suspended (its ``finally`` runs only when it is
        collected), so close() must do this too: closing the container while the thread is
        inside FFmpeg (GIL released) would free it under the decoder's feet."""
        worker = getattr(self, "_worker", None)
        if worker is None:
            return
        thread, q, stop = worker
        stop.set()
        if self._input is not None:
            self._input.close()  # the decoder may wait in its read()
        from wallcli.io.ahead import join_draining

        join_draining(thread, q)  # (the producer may wait on a full queue)
        self._worker = None

    def interrupt(self) -> None:
        """Stop decoding now, from a thread other than the one reading :meth:`frames` (which may
        wait there for a frame of a stalled stream): the decoder thread is stopped, its input
        closed, and the reader's consumer wakes to the end of its frames."""
        worker = getattr(self, "_worker", None)
        if worker is None:
            return
        self._stop_worker()
        try:
            worker[1].put_nowait(("stopped", None))
        except queue.Full:  # frames or the end are still queued: the consumer wakes to those
            pass

    def close(self) -> None:
        self._stop_worker()
        if self._input is not None:
            self._input.close()
        if self._container is not None:
            self._container.close()
            self._container = None

    def __enter__(self) -> "VideoReader":
        return self

    def __exit__(self, *exc) -> None:
        self.close()


class FrameTee:
    """A reader whose :meth:`frames` also hands every decoded frame to ``taps`` (callables), in
    order, before yielding it: one decode feeds several consumers (``wallcli evaluate`` reads the
    classifier's rows and the snr estimator from the same frames). Everything else is the reader's.
    A tap must not keep the frame's planes past its call: they view the decoder's buffers."""

    def __init__(self, reader: VideoReader, taps) -> None:
        self.reader = reader
        self.taps = tuple(taps)

    def __getattr__(self, name: str):
        return getattr(self.reader, name)

    def frames(self) -> Iterator[Frame]:
        for frame in self.reader.frames():
            for tap in self.taps:
                tap(frame)
            yield frame


class VideoWarning(UserWarning):
    """Recoverable trouble in a video (corrupt packets, truncation); the CLI prints these once."""


def open_video(source: str | os.PathLike, *, threads: int = 0, input_format: str | None = None,
               stream: int | None = None) -> VideoReader:
    """Open a path, an http(s)/rtsp URL, '-' (a streamable container on stdin) or /dev/videoN.
    ``stream``: the video stream's index in the file (default: :data:`STREAM`, else the first
    real video stream)."""
    return VideoReader(str(source), threads=threads, input_format=input_format, stream_index=stream)
