"""The peak resident memory of the process over a stretch of work, sampled by a background thread.

``resource.getrusage(...).ru_maxrss`` is the peak of the whole process's life, so it cannot tell what one stage
of a longer run needed; this samples the resident set (``/proc/self/statm`` on Linux) every few milliseconds
while the work runs and keeps the largest value. Where ``/proc`` is missing, it falls back to ``ru_maxrss``
(then the process's peak so far, an upper bound).

Why our own code: psutil would do the reading but is not a dependency; the rest is a thread and a maximum.
"""

from __future__ import annotations

import os
import threading

__all__ = ["PeakMemory", "resident_mb"]

_PAGE = os.sysconf("SC_PAGE_SIZE") if hasattr(os, "sysconf") else 4096


def resident_mb() -> float:
    """The process's resident memory now, in MB (``ru_maxrss``, the peak so far, where ``/proc`` is missing).

    >>> resident_mb() > 1.0
    True
    """
    try:
        with open("/proc/self/statm") as f:
            return int(f.read().split()[1]) * _PAGE / 2.0 ** 20
    except OSError:
        import resource
        import sys

        peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
        return peak / 2.0 ** 20 if sys.platform == "darwin" else peak / 1024.0  # bytes on macOS, KB elsewhere


class PeakMemory:
    """Context manager: ``peak_mb``, the largest resident memory (MB) sampled every ``interval`` seconds while
    the block ran (its start and end included), and ``start_mb``.

    >>> import numpy as np
    >>> with PeakMemory() as mem:
    ...     a = np.ones(2 ** 25)  # 256 MB, touched
    ...     del a
    >>> bool(mem.peak_mb - mem.start_mb > 200)
    True
    """

    def __init__(self, interval: float = 0.005):
        self.interval = float(interval)
        self.start_mb = self.peak_mb = float("nan")
        self._stop = threading.Event()
        self._thread = None

    def _sample(self):
        while not self._stop.wait(self.interval):
            self.peak_mb = max(self.peak_mb, resident_mb())

    def __enter__(self):
        self.start_mb = self.peak_mb = resident_mb()
        self._thread = threading.Thread(target=self._sample, daemon=True)
        self._thread.start()
        return self

    def __exit__(self, *exc):
        self._stop.set()
        self._thread.join()
        self.peak_mb = max(self.peak_mb, resident_mb())
        return False
