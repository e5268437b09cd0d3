"""Set-up of the worker processes of the Dask LocalCluster a campaign starts.

Dask imports this module in each worker process before the worker registers (its
``preload``, given by :func:`flexsat.campaigns.backends._dask_client`). Workers of a
cluster the user runs (``--scheduler``) are theirs and are left alone.
"""

from __future__ import annotations

import atexit
import gc


def dask_setup(worker) -> None:
    """Let the worker process exit without the interpreter's last garbage collection.

    When the cluster closes, a worker that has loaded flexsat (numba's types, the
    compiled code, xarray, pydantic's models) spends about 0.5 s of its exit in that
    collection, walking millions of objects it is about to drop with the process, and
    the campaign waits for it: a two-worker cluster took 0.80–0.87 s to close, and
    0.11–0.12 s with the collection skipped (CHANGELOG.md, 'Exits without
    the last collection'). Objects freed by reference counting are still finalized; only
    cyclic garbage (none of it holding a file or a lock a campaign writes through:
    a worker only returns rows) is left to the operating system.

    Parameters
    ----------
    worker : distributed.Worker
        The worker being started (unused: the set-up is per process).
    """
    atexit.register(gc.freeze)  # runs before the interpreter's final collection
