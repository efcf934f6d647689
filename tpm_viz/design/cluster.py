"""The atlas on a Dask distributed cluster: the only module that imports Dask (the optional extra ``.[cluster]``).

:func:`sweep_on_cluster` sends the same chunks as :func:`tpm_viz.design.atlas.sweep`'s process pool to the scheduler
at ``address`` (``tcp://HOST:PORT``) and returns the same rows in the same order. The workers must be able to
import ``tpm_viz`` (the same installation as the client).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

from distributed import Client

from tpm_viz.core.errors import InputError
from tpm_viz.core.params import Params
from tpm_viz.design.atlas import Row, chunks, run_chunk, values_of
from tpm_viz.design.indices import Settings, Task
from tpm_viz.paper.arrangement import Arrangement

__all__ = ["CONNECT_TIMEOUT", "sweep_on_cluster"]

CONNECT_TIMEOUT = 30.0
"""Seconds to wait for the scheduler."""


def sweep_on_cluster(
    address: str,
    arrangement: Arrangement,
    base: Params,
    grid: Sequence[dict[str, float]],
    task: Task,
    settings: Settings = Settings(),
    progress: Callable[[int, int], None] | None = None,
    chunk: int = 8,
) -> list[Row]:
    """The rows of :func:`tpm_viz.design.atlas.sweep`, computed by the workers of the scheduler at ``address``."""
    if not str(address).startswith(("tcp://", "tls://")):
        raise InputError(f"--scheduler expects tcp://HOST:PORT, got {repr(str(address))[:60]}")
    key = (task.x0, task.x1, task.y0, task.y1)
    jobs = [
        (Arrangement.parse(arrangement).value, values_of(base), list(c), key, settings) for c in chunks(grid, chunk)
    ]
    try:
        client = Client(address, timeout=CONNECT_TIMEOUT, set_as_default=False)
    except OSError as exc:
        raise InputError(f"cannot reach the Dask scheduler at {address}: {exc!s}") from None
    with client:
        futures = client.map(run_chunk, jobs, pure=False)
        out: list[Row] = []
        for future in futures:  # in order: a progress step as each chunk in turn is done
            out += future.result()
            if progress is not None:
                progress(len(out), len(grid))
    return out
