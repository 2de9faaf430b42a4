"""The camera thread (wallcli.io.ahead.Ahead): the same frames in the same order, an error where
the frame it stopped at would have been, a consumer that stops early stopping the thread, and
never more than its depth of frames made ahead."""
from __future__ import annotations

import threading
import time

import pytest

from wallcli.io.ahead import Ahead


class _Reader:
    def __init__(self, n, fail_at=None):
        self.n, self.fail_at = n, fail_at
        self.made = 0
        self.closed = False
        self.info = "info"

    def frames(self):
        try:
            for i in range(self.n):
                if i == self.fail_at:
                    raise ValueError(f"damaged at {i}")
                self.made += 1
                yield i
        finally:
            self.closed = True


def test_the_same_frames_in_order_and_the_reader_seen_through():
    r = _Reader(50)
    a = Ahead(r, depth=3)
    assert list(a.frames()) == list(range(50))
    assert a.info == "info" and r.closed


def test_an_error_in_the_thread_is_raised_where_its_frame_would_have_been():
    got = []
    with pytest.raises(ValueError, match="damaged at 7"):
        for f in Ahead(_Reader(20, fail_at=7)).frames():
            got.append(f)
    assert got == list(range(7))


def test_a_consumer_that_stops_early_stops_the_thread_and_the_reader():
    r = _Reader(10_000)
    before = threading.active_count()
    with Ahead(r, depth=2) as a:
        for f in a.frames():
            if f == 5:
                break
    deadline = time.monotonic() + 5
    while threading.active_count() > before and time.monotonic() < deadline:
        time.sleep(0.01)
    assert threading.active_count() == before and r.closed
    assert r.made <= 5 + 1 + 2 + 1  # what was consumed, one in hand, the queue's depth, one blocked


def test_a_consumer_that_raises_between_frames_stops_the_thread_on_leaving_the_block():
    r = _Reader(10_000)
    with pytest.raises(RuntimeError):
        with Ahead(r, depth=2) as a:
            it = a.frames()
            next(it)
            raise RuntimeError("the consumer failed")
    assert a._running is None and r.closed


def test_frames_made_ahead_stay_within_the_depth():
    r = _Reader(200)
    it = Ahead(r, depth=4).frames()
    next(it)
    time.sleep(0.2)  # the thread fills the queue and waits
    assert r.made <= 1 + 4 + 1
    assert list(it) == list(range(1, 200))
