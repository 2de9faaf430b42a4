"""Run one function over many items in worker processes, where a worker that dies is one
item's failure, not the run's.

A process that segfaults in a decoder or is killed for memory breaks a ProcessPoolExecutor:
every unfinished future then fails, the innocent with the guilty. Workers report each item they
start on a queue, so after a break the items that were being worked on are known (at most one per
worker): each of those runs again alone, in a fresh one-process pool, where dying again convicts
it; the items that never started go back to a new pool. A crash costs a few re-runs, never the
whole evaluation.
"""
from __future__ import annotations

import multiprocessing as mp
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from typing import Any, Callable, Iterator

from wallcli.errors import WallcliError

DIED = "the worker process died while analysing this clip (a crash in a decoder or library, or killed for memory)"

_started = None  # the worker's end of the start queue


def _init(started, initializer, initargs) -> None:
    global _started
    _started = started
    if initializer is not None:
        initializer(*initargs)


def _call(fn, index: int, item) -> Any:
    _started.put(index)
    return fn(item)


def imap_isolated(fn: Callable, items: list, *, jobs: int, initializer=None, initargs=(),
                  died: Callable[[int], Any] = lambda i: {"error": DIED}) -> Iterator[tuple[int, Any]]:
    """Yield (index, fn(items[index])) as they finish, in any order; an item whose worker died
    yields ``died(index)``. ``fn`` and ``initializer`` must be importable (spawned processes).
    Close the generator (``contextlib.closing``) to stop the workers early."""
    ctx = mp.get_context("spawn")  # no inherited threads or locks (decoder, progress bar) in the workers
    todo = list(range(len(items)))
    while todo:
        done: set[int] = set()
        began: set[int] = set()
        broken = False
        for index, value in _run(ctx, fn, items, todo, jobs, began, initializer, initargs):
            if index is None:
                broken = True
                break
            done.add(index)
            yield index, value
        if not broken:
            return
        suspects = [i for i in todo if i in began and i not in done]
        if not suspects:
            raise WallcliError("the worker processes could not start (see the messages above)")
        for i in suspects:  # alone, so that dying again convicts this one
            ((index, value),) = list(_run(ctx, fn, items, [i], 1, set(), initializer, initargs))
            yield i, died(i) if index is None else value
        todo = [i for i in todo if i not in done and i not in began]


def _run(ctx, fn, items, todo, jobs, began: set, initializer, initargs) -> Iterator[tuple[int | None, Any]]:
    """(index, value) per finished item; (None, None) once, last, if the pool broke. ``began``
    collects the items that workers started."""
    started = ctx.SimpleQueue()
    pool = ProcessPoolExecutor(max(1, min(jobs, len(todo))), mp_context=ctx, initializer=_init,
                               initargs=(started, initializer, initargs))
    clean = False
    try:
        futures = {pool.submit(_call, fn, i, items[i]): i for i in todo}
        pending = set(futures)
        while pending:
            finished, pending = wait(pending, return_when=FIRST_COMPLETED)
            while not started.empty():  # drained as we go: a full pipe would block the workers
                began.add(started.get())
            broke = False
            for f in finished:
                try:
                    value = f.result()
                except BrokenProcessPool:
                    broke = True
                    continue
                yield futures[f], value
            if broke:
                for f in pending:  # finished before the break, but not yet collected
                    if f.done() and not f.cancelled() and f.exception() is None:
                        yield futures[f], f.result()
                clean = True  # the executor has already stopped its workers
                yield None, None
                return
        clean = True
    finally:
        if clean:
            pool.shutdown(wait=True)
        else:
            _stop(pool)
        started.close()


def _stop(pool: ProcessPoolExecutor) -> None:
    # On Ctrl-C or an error in the parent, the workers (which ignore SIGINT) would otherwise finish
    # their clip first; terminate them. _processes is the executor's own table of its workers.
    procs = list((getattr(pool, "_processes", None) or {}).values())
    pool.shutdown(wait=False, cancel_futures=True)
    for p in procs:
        if p.is_alive():
            p.terminate()
    for p in procs:
        p.join()
