"""Where a campaign's runs run: one engine a name, each yielding results as runs finish.

An engine takes the run function and the jobs and yields ``(job, summary, error, worker)`` in
the order the runs *finish* (``summary`` None and ``error`` set when the run function raised;
``worker`` names where it ran), so the campaign writes every row as soon as it exists:

- ``serial``: this process, one run after the other (``--jobs 1``);
- ``processes``: a local process pool (``--jobs N``, the default over every core);
- ``dask``: tasks on an existing Dask cluster (``--scheduler tcp://HOST:PORT``); mobigrasp must be
  importable on the scheduler and every worker (docs/campaigns.md). Needs ``mobigrasp[cluster]``.

``ENGINES`` is the registry by name; :func:`open_engine` refuses an unknown name by name.
"""

from __future__ import annotations

import os
import re
import socket
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import Executor, ProcessPoolExecutor, as_completed

Result = tuple[dict, dict | None, str | None, str]
RunFn = Callable[[dict], dict]
SCHEDULER_URL = re.compile(r"(tcp|tls)://[A-Za-z0-9_.\-\[\]:]+:\d{1,5}")
CONNECT_TIMEOUT_S = 20  # reaching the scheduler; a safety limit, not a performance figure


class EngineError(ValueError):
    """The engine cannot start (bad scheduler address, scheduler unreachable): exit 2."""


def _here() -> str:
    return f"{socket.gethostname()}/pid {os.getpid()}"


def _error(exc: BaseException) -> str:
    return f"{type(exc).__name__}: {exc}"


def serial(run_fn: RunFn, jobs: Iterable[dict], workers: int = 1,
           scheduler: str | None = None) -> Iterator[Result]:
    """Every run in this process, in order."""
    for job in jobs:
        try:
            yield job, run_fn(job), None, _here()
        except Exception as exc:  # one broken run must not end the campaign
            yield job, None, _error(exc), _here()


def _in_worker_process(run_fn: RunFn, job: dict) -> tuple[dict, str]:
    return run_fn(job), _here()


def processes(run_fn: RunFn, jobs: Iterable[dict], workers: int = 2,
              scheduler: str | None = None,
              pool_factory: Callable[..., Executor] = ProcessPoolExecutor) -> Iterator[Result]:
    """A pool of ``workers`` local processes; results as they finish. Stopped early (Ctrl-C,
    the campaign killed, the consumer gone) the runs not started are dropped and the pool is
    not waited for: a pool left to its own shutdown would go on to run every one of them
    without anyone recording their rows."""
    pool = pool_factory(max_workers=workers)
    finished = False
    try:
        futures = {pool.submit(_in_worker_process, run_fn, job): job for job in jobs}
        for fut in as_completed(futures):
            try:
                summary, where = fut.result()
                yield futures[fut], summary, None, where
            except Exception as exc:
                yield futures[fut], None, _error(exc), "unknown (the run raised)"
        finished = True
    finally:
        pool.shutdown(wait=finished, cancel_futures=True)


def _in_dask_worker(run_fn: RunFn, job: dict) -> tuple[dict, str]:
    from distributed import get_worker

    return run_fn(job), get_worker().address


def check_scheduler(address: str) -> str:
    """``tcp://HOST:PORT`` (or ``tls://``); EngineError naming ``--scheduler`` otherwise."""
    if not isinstance(address, str) or not SCHEDULER_URL.fullmatch(address):
        raise EngineError(f"--scheduler must be tcp://HOST:PORT (or tls://...), got {address!r}")
    if not 0 < int(address.rsplit(":", 1)[1]) < 65536:
        raise EngineError(f"--scheduler: port out of range in {address!r}")
    return address


def dask(run_fn: RunFn, jobs: Iterable[dict], workers: int = 0,
         scheduler: str | None = None) -> Iterator[Result]:
    """One Dask task per run on the cluster at ``scheduler``; results as they finish. A task
    is one whole closed-loop run (seconds), so the per-task cost of Dask is not felt."""
    try:
        from distributed import Client
        from distributed import as_completed as dask_completed
    except ImportError as exc:
        raise EngineError("--scheduler needs dask.distributed: pip install "
                          "'mobigrasp[cluster]'") from exc
    address = check_scheduler(scheduler or "")
    host, port = address.split("://", 1)[1].rsplit(":", 1)
    try:  # a refused port fails at once here (the client would retry until its timeout)
        socket.create_connection((host.strip("[]"), int(port)), timeout=CONNECT_TIMEOUT_S).close()
        client = Client(address, timeout=CONNECT_TIMEOUT_S, set_as_default=False)
    except (OSError, TimeoutError) as exc:
        raise EngineError(f"--scheduler {address}: cannot reach the scheduler "
                          f"({_error(exc)})") from exc
    try:
        futures = {}
        for job in jobs:
            key = f"mobigrasp-run-{job['method']}-{job['seed']}-{os.getpid()}"
            futures[client.submit(_in_dask_worker, run_fn, job, key=key, pure=False)] = job
        for fut in dask_completed(list(futures), loop=client.loop):
            job = futures[fut]
            try:
                summary, where = fut.result()
                yield job, summary, None, where
            except Exception as exc:  # the run raised on its worker, or the worker died
                yield job, None, _error(exc), "unknown (the run raised)"
    finally:
        client.close()


ENGINES: dict[str, Callable[..., Iterator[Result]]] = {
    "serial": serial, "processes": processes, "dask": dask}


def open_engine(name: str) -> Callable[..., Iterator[Result]]:
    """The engine called ``name``; EngineError listing the known names otherwise."""
    try:
        return ENGINES[name]
    except KeyError:
        raise EngineError(f"unknown campaign engine {name!r}: one of "
                          f"{', '.join(sorted(ENGINES))}") from None
