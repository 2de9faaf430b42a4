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
from contextlib import contextmanager
from typing import Any, Callable, Iterator

from wallcli.errors import WallcliError

# Dask's scheduler retries a task whose worker died this many times before giving up on it
# (KilledWorker): a video that kills its worker is tried once more, then becomes an error line.
ALLOWED_FAILURES = 1

# Seconds to reach a --scheduler and complete Dask's handshake with it (cli/scan.py says so in
# --help). Dask's own connect() waits for the other side's handshake without a limit: an HTTP
# server on the port kept a scan waiting for ever.
CONNECT_TIMEOUT = 20.0


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


def _first_line(exc: BaseException) -> str:
    text = str(exc).strip()
    return text.splitlines()[0] if text else type(exc).__name__


@contextmanager
def _terminal_signals_held() -> Iterator[Callable[[], None]]:
    """Start the local cluster with Ctrl-C, a closed terminal and `kill` held back; yields a
    function that holds them again (for code that unblocks them: multiprocessing does).

    A terminal sends Ctrl-C (and SIGHUP) to every process of its foreground group, Dask's worker
    processes included: each printed a KeyboardInterrupt traceback, and one landing in the
    cluster's start-up left it half made (``AssertionError: Status.init``). Threads and
    processes inherit a blocked signal: Dask's threads and every process started here (or later,
    by those threads, to replace a dead worker) never receive these, and the workers are stopped
    by this process instead, in order. This thread's own signals wait until the cluster is up,
    then land as usual.
    """
    import signal

    held = {getattr(signal, n) for n in ("SIGINT", "SIGTERM", "SIGHUP") if hasattr(signal, n)}
    if not hasattr(signal, "pthread_sigmask") or not held:
        yield lambda: None
        return
    before = signal.pthread_sigmask(signal.SIG_BLOCK, held)
    try:
        yield lambda: signal.pthread_sigmask(signal.SIG_BLOCK, held)
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, before)


def _worker_interpreter_problem() -> str | None:
    """Why this interpreter cannot start a worker process, or None.

    Dask's worker processes run it. One this user may not run (or that exits at once) fails deep
    in Dask ('Nanny failed to start'), after multiprocessing made locks whose clean-up then
    prints BrokenPipeError tracebacks at exit, and after the failing processes wrote to our
    stderr. Started here first (a few hundredths of a second), it is one line saying why.
    """
    import subprocess
    from multiprocessing import spawn

    exe = os.fsdecode(spawn.get_executable())
    try:
        run = subprocess.run([exe, "-c", "import multiprocessing.spawn"], stdin=subprocess.DEVNULL,
                             capture_output=True, timeout=120)
    except OSError as err:
        reason = err.strerror or str(err)
        return f"its worker processes cannot run {exe} ({reason[:1].lower() + reason[1:]})"
    except subprocess.TimeoutExpired:
        return f"a worker process ({exe}) did not start within 120 s"
    if run.returncode != 0:
        tail = run.stderr.decode("utf-8", "replace").strip().splitlines()
        return f"a worker process ({exe}) exits at once: {tail[-1] if tail else f'status {run.returncode}'}"
    return None


def _why_not_started(exc: BaseException) -> str:
    """Dask's own words ('Nanny failed to start.') and the first failure under them."""
    root = exc
    while root.__cause__ is not None or root.__context__ is not None:
        root = root.__cause__ or root.__context__
    return f"{_first_line(exc)} ({type(root).__name__}: {_first_line(root)})" if root is not exc else _first_line(exc)


def _handshake(address: str, timeout: float) -> None:
    """Connect to ``address`` and complete Dask's handshake within ``timeout`` seconds, or fail
    with a line naming the address. Dask's Client waits for the handshake for ever and believes
    whatever comes back (an HTTP server hung it; garbage made it allocate exabytes)."""
    import asyncio

    from distributed.comm import connect
    from distributed.comm.addressing import parse_address, parse_host_port
    from distributed.comm.registry import get_backend

    from wallcli.errors import UsageError

    try:
        scheme, location = parse_address(address)
        get_backend(scheme)
        if scheme in ("tcp", "tls", "ws", "wss"):
            parse_host_port(location)
    except (ValueError, TypeError) as exc:
        raise UsageError(f"--scheduler {address} is not a Dask scheduler address ({_first_line(exc)})",
                         hint="e.g. tcp://10.0.0.5:8786") from None

    async def shake() -> Any:
        comm = await asyncio.wait_for(connect(address, timeout=timeout), timeout)
        try:
            return comm.remote_info
        finally:
            comm.abort()

    try:
        info = asyncio.run(shake())
    except (asyncio.TimeoutError, TimeoutError):
        raise WallcliError(f"{address} did not answer as a Dask scheduler within {timeout:g} s "
                           "(is it one? is the port right?)") from None
    except OSError as exc:
        raise WallcliError(f"cannot reach the Dask scheduler at {address}: {_first_line(exc)}") from None
    except (KeyboardInterrupt, WallcliError):
        raise
    except (Exception, MemoryError):  # noqa: BLE001 - garbage read as a message: any decoder error
        raise WallcliError(f"{address} answered, but not as a Dask scheduler") from None
    if not isinstance(info, dict) or "pickle-protocol" not in info:
        raise WallcliError(f"{address} answered, but not as a Dask scheduler")


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
        # distributed's defaults must be in the config before dask.config.set() below saves it:
        # otherwise leaving set() removes every distributed.* key, under a cluster still closing
        import distributed  # noqa: F401

        logging.getLogger("distributed").setLevel(self.level)
        # one task per worker thread at a time: a worker that dies then takes down one video, not
        # also the next one queued on it (which Dask would count as a failure of that one too)
        self._config = dask.config.set({"distributed.scheduler.allowed-failures": ALLOWED_FAILURES,
                                        "distributed.scheduler.worker-saturation": 1.0})
        self._config.__enter__()
        try:
            if self.scheduler is None:
                self._start_local()
            else:
                self._connect()
                self._check_workers()
            if self.scheduler is not None or _has_dashboard():
                # a remote scheduler's dashboard is its own business: announce what it serves
                if "dashboard" in (self.client.scheduler_info().get("services") or {}):
                    self.log(f"Dask dashboard: {self.client.dashboard_link}")
        except BaseException:
            self.close()
            raise
        return self

    def _start_local(self) -> None:
        from multiprocessing import resource_tracker

        from distributed import Client, LocalCluster

        problem = _worker_interpreter_problem()
        if problem:
            raise WallcliError(f"the local Dask cluster could not start: {problem}")
        try:
            with _terminal_signals_held() as hold_again:
                # multiprocessing's resource tracker (a process) starts with the blocked signals
                # it inherits, then unblocks SIGINT and SIGTERM in the thread that started it:
                # started here, first, it keeps SIGHUP held too, and Dask's thread that would
                # otherwise start it keeps its block for the workers
                resource_tracker.ensure_running()
                hold_again()
                # loopback only: a cluster on this machine has no business listening on the network
                # (Dask moves to a free port when 8787 is taken; without bokeh there is no dashboard
                # and its placeholder page goes on any free port)
                self.cluster = LocalCluster(n_workers=self.workers, threads_per_worker=1, processes=True,
                                            host="127.0.0.1",
                                            dashboard_address="127.0.0.1:8787" if _has_dashboard() else "127.0.0.1:0",
                                            silence_logs=self.level)
                self.client = Client(self.cluster)
        except (KeyboardInterrupt, WallcliError, MemoryError):
            raise
        except Exception as exc:  # noqa: BLE001 - Dask's own failure to start is the user's one line
            raise WallcliError(f"the local Dask cluster could not start: {_why_not_started(exc)}") from None

    def _connect(self) -> None:
        from distributed import Client

        address = self.scheduler
        _handshake(address, CONNECT_TIMEOUT)
        try:
            self.client = Client(address, timeout=f"{CONNECT_TIMEOUT}s")
        except (KeyboardInterrupt, WallcliError):
            raise
        except Exception as exc:  # noqa: BLE001 - whatever went wrong, it is this address's fault
            raise WallcliError(f"cannot use the Dask scheduler at {address}: {_first_line(exc)}") from None

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
