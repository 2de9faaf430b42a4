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

import os
import queue
import threading
import warnings
from contextvars import ContextVar
from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path
from typing import Iterator

from wallcli.errors import WallcliError
# the planes a frame decodes to (importable from here too, as before the split)
from wallcli.io.planes import Planes, frame_planes, quarter_turns, rotate_planes  # noqa: F401
# byte streams, what an input is, and frame rates and times live beside this file; their names
# stay importable from here, where callers have always found them
from wallcli.io.byte_stream import FLUSH_FACTOR, StreamInput, _byte_stream, _front_to_back, _Stopped  # noqa: F401
from wallcli.io.rates import (GAP_FACTOR, GAP_HISTORY, GAP_MIN, MAX_FPS, MIN_FPS, RATE_PROBE,  # noqa: F401
                              RATE_TOLERANCE, RAW_DEFAULT_FPS, RAW_DEMUXERS, FrameClock, check_rate,
                              container_rate)
from wallcli.io.sources import (REENCODED, STDIN_MP4, NotAVideo, _describe_open_error, _is_url,  # noqa: F401
                                _real_video)


# The video stream to read (its index in the file, as ffprobe numbers them), for commands given
# --stream N (cli.common.use_stream); None: the first real video stream
STREAM: ContextVar[int | None] = ContextVar("wallcli_stream", default=None)

# How long a byte stream (stdin, a FIFO, <(...)) may send nothing before the read fails saying so,
# for commands given --stall-timeout (cli.common.use_stream); None: wait for ever (a live feed)
DEFAULT_STALL = 30.0
STALL: ContextVar[float | None] = ContextVar("wallcli_stall", default=DEFAULT_STALL)
# --follow on a regular file: read it as it grows, until it has not grown for this many seconds
# (None: read what is there, as any file)
FOLLOW_IDLE: ContextVar[float | None] = ContextVar("wallcli_follow_idle", default=None)


_QUEUE_SIZE = 8


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
    # the stream's time base: its timestamps are whole multiples of it, so a frame's time is exact
    # to one tick of it (a millisecond in Matroska: a 240 fps clip's frames are 4 or 5 ms apart)
    time_base: Fraction | None = None


@dataclass
class Frame:
    index: int
    time: float
    planes: Planes
    _keep: object = field(default=None, repr=False)  # the av.VideoFrame whose buffers the planes view
    gap: float = 0.0  # seconds since the frame before, when the timestamps jump there (frames lost): 0 otherwise

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
        container_name = str(self._container.format.name or "")
        try:
            fps, fps_source = container_rate(stream, container_name, source,
                                             lambda m, loud: self._warn(m) if loud else self.warnings.append(m))
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
            time_base=Fraction(stream.time_base) if stream.time_base else None,
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
        self._clock = FrameClock(stream.time_base, fps, source)  # frame times, gaps and measured rate

    @property
    def gaps(self) -> list[tuple[float, float]]:
        """(time of the frame before, time of the frame after) per jump of the timestamps (frames lost)."""
        return self._clock.gaps

    @property
    def measured_fps(self) -> float | None:
        """The frames' own rate so far: intervals counted, gaps (frames lost) not; None before two frames."""
        return self._clock.measured_fps

    @property
    def fps(self) -> float:
        """The rate to report once the frames are read: the container's, unless the timestamps say
        otherwise by more than RATE_TOLERANCE (a stream labelled 30 fps whose frames are 0.1 s
        apart, a 30 fps GIF whose 3-3-4 centisecond delays are read as 33.3 fps)."""
        got, said = self.measured_fps, float(self.info.fps)
        if got is None or abs(got - said) <= RATE_TOLERANCE * said:
            return said
        # as a rate is stated (stplot's fps_fraction): 25, not the 24.999999999999996 a sum of intervals gives
        return float(Fraction(got).limit_denominator(1001))

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
        clock = self._clock = FrameClock(self._stream.time_base, self.info.fps, self.source)
        size = None  # (width, height) of the first frame: every analysis holds per-pixel state of that size
        try:
            while True:
                kind, item = q.get()
                if kind == "frame":
                    frame = item
                    t, gap = clock.stamp(frame.pts, index)
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
                    clock.check_intervals()
                    self._check_complete(index, clock.last_time)
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
