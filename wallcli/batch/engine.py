"""Where the tasks run: a Dask ``LocalCluster`` on this machine, or an existing Dask scheduler.

Dask does the distributing (scheduling, a worker per core, restarting dead workers, moving
work off them); this module only configures it for wallcli's kind of task (one video, seconds to
hours of one core each, no data passed between tasks) and checks that remote workers would give
the client's answers.
"""
from __future__ import annotations

import logging
import os
import uuid
from typing import Any, Callable, Iterator

from wallcli.errors import WallcliError

# Dask's scheduler retries a task whose worker died this many times before giving up on it
# (KilledWorker): a video that kills its worker is tried once more, then becomes an error line.
ALLOWED_FAILURES = 1


def default_workers() -> int:
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # not Linux
        return max(1, os.cpu_count() or 1)


def _has_dashboard() -> bool:
    import importlib.util

    # the dashboard needs bokeh, which dask[distributed] does not install; without it Dask still
    # serves a page saying so at the dashboard's address, which is not worth announcing
    return importlib.util.find_spec("bokeh") is not None


class Engine:
    """``with Engine(...) as e: for item, line in e.map(fn, items, config): ...``"""

    def __init__(self, *, workers: int | None = None, scheduler: str | None = None,
                 log: Callable[[str], None] = lambda m: None, debug: bool = False):
        self.workers = workers or default_workers()
        self.scheduler = scheduler
        self.log = log
        self.level = logging.WARNING if debug else logging.CRITICAL
        self.cluster = self.client = None
        self._config = None

    # -- start / stop -------------------------------------------------------------------------
    def __enter__(self) -> "Engine":
        import dask
        from distributed import Client, LocalCluster

        logging.getLogger("distributed").setLevel(self.level)
        # one task per worker thread at a time: a worker that dies then takes down one video, not
        # also the next one queued on it (which Dask would count as a failure of that one too)
        self._config = dask.config.set({"distributed.scheduler.allowed-failures": ALLOWED_FAILURES,
                                        "distributed.scheduler.worker-saturation": 1.0})
        self._config.__enter__()
        try:
            if self.scheduler is None:
                # loopback only: a cluster on this machine has no business listening on the network
                # (Dask moves to a free port when 8787 is taken; without bokeh there is no dashboard
                # and its placeholder page goes on any free port)
                self.cluster = LocalCluster(n_workers=self.workers, threads_per_worker=1, processes=True,
                                            host="127.0.0.1",
                                            dashboard_address="127.0.0.1:8787" if _has_dashboard() else "127.0.0.1:0",
                                            silence_logs=self.level)
                self.client = Client(self.cluster)
            else:
                try:
                    self.client = Client(self.scheduler, timeout="20s")
                except (OSError, TimeoutError, ValueError) as exc:
                    raise WallcliError(f"cannot reach the Dask scheduler at {self.scheduler}: "
                                       f"{str(exc).splitlines()[0] if str(exc) else type(exc).__name__}") from None
                self._check_workers()
            if self.scheduler is not None or _has_dashboard():
                # a remote scheduler's dashboard is its own business: announce what it serves
                if "dashboard" in (self.client.scheduler_info().get("services") or {}):
                    self.log(f"Dask dashboard: {self.client.dashboard_link}")
        except BaseException:
            self.close()
            raise
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def close(self) -> None:
        for thing in (self.client, self.cluster):
            if thing is not None:
                try:
                    thing.close()
                except Exception:  # noqa: BLE001 - closing after a failure: the first error matters
                    pass
        self.client = self.cluster = None
        if self._config is not None:
            self._config.__exit__(None, None, None)
            self._config = None

    def _check_workers(self) -> None:
        from wallcli.batch.task import describe, identity

        try:
            self.client.wait_for_workers(1, timeout=60)
        except (TimeoutError, OSError):
            raise WallcliError(f"the Dask scheduler at {self.scheduler} has no workers "
                               "(start some with 'dask worker ADDRESS')") from None
        mine = identity()
        try:
            theirs = self.client.run(identity)
        except Exception as exc:  # noqa: BLE001 - a worker that cannot import wallcli fails here
            raise WallcliError(f"the workers of {self.scheduler} cannot run wallcli ({type(exc).__name__}: "
                               f"{str(exc).splitlines()[0] if str(exc) else ''})",
                               hint="install the same wallcli on every worker") from None
        for address, ident in sorted(theirs.items()):
            if ident != mine:
                raise WallcliError(f"worker {address} runs {describe(ident)}, this client {describe(mine)}",
                                   hint="install the same wallcli on the workers and here")
        self.workers = len(theirs)

    # -- work ---------------------------------------------------------------------------------
    def map(self, fn: Callable, items: list, *args: Any,
            failed: Callable[[Any, str], Any]) -> Iterator[tuple[Any, Any]]:
        """``(item, fn(item, *args))`` as each finishes, in any order.

        A task that Dask gives up on (its worker died, twice) or that raised gives
        ``failed(item, message)`` instead. Leaving the loop early (Ctrl-C) cancels what is left.
        """
        from distributed import as_completed
        from distributed.scheduler import KilledWorker

        run = uuid.uuid4().hex[:8]
        futures = {}
        for i, item in enumerate(items):
            # pure=False: a second scan of the same file is new work, not a cached answer
            fut = self.client.submit(fn, item, *args, key=f"wallcli-scan-{run}-{i}", pure=False)
            futures[fut.key] = (fut, item)
        pending = [f for f, _ in futures.values()]
        try:
            for fut in as_completed(pending):
                item = futures[fut.key][1]
                try:
                    value = fut.result()
                except KilledWorker:
                    value = failed(item, f"the worker processing it died ({ALLOWED_FAILURES + 1} tries)"
                                   if self.scheduler is None else "the workers processing it died")
                except Exception as exc:  # noqa: BLE001 - one task's failure is one error line
                    value = failed(item, f"{type(exc).__name__}: {exc}")
                fut.release()
                del futures[fut.key]
                yield item, value
        finally:
            if futures and self.client is not None:
                try:
                    self.client.cancel([f for f, _ in futures.values()])
                except Exception:  # noqa: BLE001 - shutting down anyway
                    pass
