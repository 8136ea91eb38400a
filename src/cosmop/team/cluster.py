"""The robots' syntheses on a Dask cluster: connect to a scheduler and hand its workers the work.

:func:`cosmop.team.loop.plan_team` runs each robot's synthesis wherever its ``executor`` says
(any :class:`concurrent.futures.Executor`); the syntheses are independent and deterministic,
so the plans do not depend on where they ran.  This module gives the executor of a Dask
cluster: :func:`dask_executor` connects to a scheduler (``tcp://host:8786``), checks that it
has workers and that every worker runs this version of cosmop, and yields
``Client.get_executor()``.

Dask (``distributed``) is optional: ``pip install 'cosmop[cluster]'`` on the machine that
plans and on every worker.  A cluster over several machines::

    dask scheduler                                          # on one machine: tcp://HOST:8786
    dask worker tcp://HOST:8786 --nworkers 2 --nthreads 1   # on every other machine
    cosmop plan scenario.yaml -o plans.json --scheduler tcp://HOST:8786

One thread per worker process: a synthesis is mostly Python (the encoding) and Z3, which
share the interpreter's lock in one process; processes, not threads, run syntheses side by
side.  Each synthesis builds its own Z3 context, so threads are safe, only not faster.

Examples
--------
>>> from cosmop.team.cluster import dask_executor
>>> with dask_executor("tcp://127.0.0.1:1", timeout=0.5) as executor:  # nothing listens there
...     pass
Traceback (most recent call last):
...
cosmop.team.cluster.ClusterError: scheduler: ...
"""

from __future__ import annotations

from collections.abc import Iterator
from concurrent.futures import Executor
from contextlib import contextmanager
from typing import Any

from cosmop.errors import CosmopInputError

__all__ = ["DEFAULT_TIMEOUT", "ClusterError", "dask_executor", "worker_version"]

DEFAULT_TIMEOUT = 10.0
"""Seconds to wait for the scheduler to answer and for its first worker to join."""


class ClusterError(CosmopInputError):
    """A Dask scheduler that cannot be used: Dask missing here, no answer, no workers, or
    workers without this version of cosmop.  The command line prints it and exits with 2."""


def worker_version() -> str:
    """This process's cosmop version, once it has imported what a synthesis runs (Z3, shapely).

    Run on each worker when connecting: a worker that cannot plan fails here, before any work
    is submitted, and the imports (about a second) are not paid by the first synthesis.
    """
    import cosmop.team.planner  # noqa: F401  (the module the syntheses are pickled from)
    from cosmop._version import __version__

    return __version__


@contextmanager
def dask_executor(
    address: str, *, timeout: float | None = None, field: str = "scheduler"
) -> Iterator[Executor]:
    """Yield the executor of the Dask cluster whose scheduler listens at `address`.

    Parameters
    ----------
    address : str
        The scheduler's address, e.g. ``tcp://10.0.0.5:8786``.
    timeout : float, optional
        Seconds to wait for the scheduler and for at least one worker (default
        :data:`DEFAULT_TIMEOUT`).
    field : str
        How error messages name the address (the command line passes ``--scheduler``).

    Raises
    ------
    ClusterError
        When Dask is not installed, the scheduler does not answer within `timeout`, no worker
        joins within `timeout`, or a worker cannot import cosmop or runs another version.
        Nothing has been submitted then.
    """
    timeout = DEFAULT_TIMEOUT if timeout is None else timeout
    client = _connect(address, timeout, field)
    try:
        _check_workers(client, address, timeout, field)
        with client.get_executor(pure=False) as executor:
            yield executor
    finally:
        client.close()


def _connect(address: str, timeout: float, field: str) -> Any:
    try:
        from distributed import Client
    except ImportError:
        raise ClusterError(
            "a Dask scheduler needs Dask on this machine: pip install 'cosmop[cluster]'", field=field
        ) from None
    try:
        return Client(address, timeout=timeout, set_as_default=False)  # type: ignore[no-untyped-call]  # distributed leaves Client() unannotated
    except (OSError, TimeoutError, ValueError) as err:
        raise ClusterError(
            f"expected a Dask scheduler at {address}: none answered within {timeout:g} s ({err})",
            field=field,
        ) from None


def _check_workers(client: Any, address: str, timeout: float, field: str) -> None:
    """At least one worker, each with this cosmop (a missing one would fail every synthesis)."""
    from cosmop._version import __version__

    try:
        client.wait_for_workers(1, timeout=timeout)
    except TimeoutError:
        raise ClusterError(
            f"the Dask scheduler at {address} has no workers (none joined within {timeout:g} s); "
            f"start some with: dask worker {address} --nthreads 1",
            field=field,
        ) from None
    try:
        versions = client.run(worker_version)
    except Exception as err:  # whatever the worker raised while unpickling or running it
        raise ClusterError(
            f"the workers of {address} cannot run cosmop ({type(err).__name__}: {err}); "
            f"install cosmop {__version__} on every worker: pip install 'cosmop[cluster]'",
            field=field,
        ) from None
    other = {worker: v for worker, v in versions.items() if v != __version__}
    if other:
        worker, version = sorted(other.items())[0]
        raise ClusterError(
            f"every worker of {address} must run cosmop {__version__}; {worker} runs {version}",
            field=field,
        )
