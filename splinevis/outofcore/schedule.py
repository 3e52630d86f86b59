"""Running a dask graph with a progress bar, on whatever scheduler is active.

Why our own code: dask's local schedulers report progress through callbacks
(:class:`dask.diagnostics.ProgressBar`), a ``dask.distributed`` cluster through futures
(:func:`distributed.progress`). The store writers call :func:`run` and work unchanged on both: with a
``distributed.Client`` created (it becomes the default), the graph goes to the cluster; otherwise the
threaded scheduler runs it (``dask.config.set(num_workers=n)`` sets its threads).
"""

from __future__ import annotations

__all__ = ["active_client", "run"]


def active_client():
    """The default ``distributed.Client`` if one exists, else None.

    Examples
    --------
    >>> active_client() is None  # no cluster in the doctests: the threaded scheduler runs the graphs
    True
    """
    try:
        from distributed import default_client
    except ImportError:  # pragma: no cover - distributed is a dependency
        return None
    try:
        return default_client()
    except ValueError:
        return None


def run(task, *, progress=True, label=""):
    """Compute ``task`` (a dask collection or delayed) and return its value, with a progress bar.

    Parameters
    ----------
    task : dask collection or Delayed
    progress : bool
        Show a text progress bar (dask's ``ProgressBar`` locally, ``distributed.progress`` on a cluster).
    label : str
        Printed before the bar.

    Examples
    --------
    >>> import dask.array as da
    >>> float(run(da.ones((4, 4), chunks=2).sum(), progress=False))
    16.0
    """
    import dask

    client = active_client()
    if progress and label:
        print(label, flush=True)
    if client is not None:
        future = client.compute(task)
        if progress:
            from distributed import progress as _progress

            _progress(future)
        return client.gather(future)  # a future, or a list of them for a list-like task
    if progress:
        from dask.diagnostics import ProgressBar

        with ProgressBar():
            return dask.compute(task)[0]
    return dask.compute(task)[0]
