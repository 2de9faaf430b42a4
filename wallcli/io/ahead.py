"""A reader whose frames are made in a thread of their own, a few frames ahead of their consumer.

The camera pipeline's checks (repeats, overlays, interlace, the view, the noise's correlation) and
the projection of each frame onto the plots are two halves of the per-frame work. Run in one
thread, each frame waits for both; with the checks in a thread of their own, the projection and
the nets of one frame run while the checks of the next one do, and both while the decoder's threads
work on the frames after (numpy and OpenCV release the GIL in their loops). Bounded: ``depth``
frames at most wait in the queue, so memory stays flat whatever the clip's length.
"""
from __future__ import annotations

import queue
import threading
from typing import Iterator

DEPTH = 4


class Ahead:
    """``reader``'s frames, made by a thread of ours; everything else is the reader's. An error in
    the thread (a damaged file, a frame of another size) is raised in the consumer's, where the
    frame it stopped at would have been; a consumer that stops early stops the thread."""

    def __init__(self, reader, depth: int = DEPTH) -> None:
        self.reader = reader
        self.depth = int(depth)
        self._running = None  # (thread, queue, stop event) while frames() runs

    def __getattr__(self, name: str):
        return getattr(self.reader, name)

    def frames(self) -> Iterator:
        q: queue.Queue = queue.Queue(maxsize=self.depth)
        stop = threading.Event()

        def put(item) -> bool:
            while not stop.is_set():
                try:
                    q.put(item, timeout=0.05)
                    return True
                except queue.Full:
                    continue
            return False

        def run() -> None:
            frames = self.reader.frames()
            try:
                for frame in frames:
                    if not put(("frame", frame)):
                        break
            except BaseException as exc:  # noqa: BLE001 - handed to the consumer
                put(("error", exc))
            else:
                put(("end", None))
            finally:
                frames.close()  # the readers below stop their own threads here

        worker = threading.Thread(target=run, daemon=True, name="wallcli-camera")
        self._running = (worker, q, stop)
        worker.start()
        try:
            while True:
                kind, item = q.get()
                if kind == "frame":
                    yield item
                elif kind == "error":
                    raise item
                else:
                    return
        finally:
            self.close()

    def close(self) -> None:
        """Stop the thread and wait for it (a consumer that raised between frames leaves the
        generator suspended: the ``with`` block around it calls this)."""
        if self._running is None:
            return
        worker, q, stop = self._running
        self._running = None
        stop.set()
        if worker.is_alive():
            # the thread may wait inside the reader for a frame that is not coming (a stalled
            # stream, its consumer interrupted): the reader stops its decoder and wakes it
            interrupt = getattr(self.reader, "interrupt", None)
            if interrupt is not None:
                interrupt()
        join_draining(worker, q)

    def __enter__(self) -> "Ahead":
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def join_draining(thread: threading.Thread, q: queue.Queue) -> None:
    """Wait for ``thread`` to end, emptying ``q`` meanwhile: a producer blocked on the full queue
    then gets to see that it was told to stop."""
    while thread.is_alive():
        try:
            q.get_nowait()
        except queue.Empty:
            thread.join(timeout=0.05)
