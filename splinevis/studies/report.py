"""What every study shares in writing its results: number formats, markdown tables (with the columns
labelled "paper"), NaN-free JSON, a log line and progress bars, frame timing rows, error summaries and
figures saved the one way.

The studies (:mod:`splinevis.studies.terrain`, :mod:`splinevis.studies.volume`, the showcase in
:mod:`splinevis.studies.demo`) import these helpers from here and from nowhere else; no study imports
another study's private helpers.

The "paper" convention: a number taken from a paper is never mixed with a measured one. It appears only
in a column whose label starts with ``paper`` (:func:`paper_columns`) or in a table of its own whose
heading and first column say ``paper`` (:func:`paper_table`).
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import numpy as np

__all__ = ["fmt", "md_table", "PAPER", "paper_columns", "paper_table", "clean", "write_json", "log",
           "progress_bar", "timed", "error_summary", "pyplot", "save_figure"]

#: The label of every column and table that shows a paper's numbers rather than measured ones.
PAPER = "paper"


# ---------------------------------------------------------------------------------------- numbers, tables
def fmt(value, kind: str = "s") -> str:
    """One table cell.

    Parameters
    ----------
    value : object
        The number (or anything else for ``kind="s"``); ``None`` is shown as ``-``.
    kind : {"s", "e", "f1", "f2", "int"}
        ``"e"`` two-digit mantissa exponential, ``"f1"`` / ``"f2"`` one / two decimals, ``"int"`` an integer
        with thousands separators, anything else ``str(value)``.

    Returns
    -------
    str

    Examples
    --------
    >>> fmt(0.000123456, "e"), fmt(3.14159, "f1"), fmt(3.14159, "f2"), fmt(1234567.8, "int")
    ('1.23e-04', '3.1', '3.14', '1,234,567')
    >>> fmt(None, "e"), fmt(True, "s"), fmt("blocks")
    ('-', 'True', 'blocks')
    """
    if value is None:
        return "-"
    if kind == "e":
        return f"{value:.2e}"
    if kind == "f1":
        return f"{value:.1f}"
    if kind == "f2":
        return f"{value:.2f}"
    if kind == "int":
        return f"{int(value):,}"
    return str(value)


def md_table(rows, cols, formatter=fmt) -> str:
    """A markdown table: a header line, a separator line and one line per row, each ending in a newline.

    Parameters
    ----------
    rows : iterable of dict
        A missing key is a ``None`` cell.
    cols : sequence of (label, key, kind)
        The column's header, the row key it shows and the ``kind`` passed to ``formatter``.
    formatter : callable, optional
        ``formatter(value, kind) -> str``; :func:`fmt` by default.

    Returns
    -------
    str

    Examples
    --------
    >>> rows = [{"scheme": "C1", "rms": 0.00123, "patches": 1152}, {"scheme": "C2"}]
    >>> print(md_table(rows, [("scheme", "scheme", "s"), ("rms", "rms", "e"), ("patches", "patches", "int")]), end="")
    | scheme | rms | patches |
    |---|---|---|
    | C1 | 1.23e-03 | 1,152 |
    | C2 | - | - |
    """
    head = "| " + " | ".join(c[0] for c in cols) + " |\n|" + "|".join("---" for _ in cols) + "|\n"
    return head + "".join("| " + " | ".join(formatter(r.get(c[1]), c[2]) for c in cols) + " |\n" for r in rows)


def paper_columns(cols) -> list:
    """The same columns with their labels marked as a paper's numbers (``"paper <label>"``).

    Parameters
    ----------
    cols : sequence of (label, key, kind)

    Returns
    -------
    list of (label, key, kind)

    Examples
    --------
    >>> paper_columns([("rms", "paper_rms_rel", "e"), ("max", "paper_max_rel", "e")])
    [('paper rms', 'paper_rms_rel', 'e'), ('paper max', 'paper_max_rel', 'e')]
    """
    return [(f"{PAPER} {label}", key, kind) for label, key, kind in cols]


def paper_table(source: str, rows, cols) -> str:
    """A table of a paper's numbers only: a level-3 heading ``### paper (<source>)`` and a table whose first
    column is labelled ``paper <label>``, so that it stays labelled when copied without its heading.

    Parameters
    ----------
    source : str
        Where the numbers come from (citation key, table, hardware).
    rows : iterable of dict
    cols : sequence of (label, key, kind)
        As in :func:`md_table`; only the first label gets the ``paper`` mark.

    Returns
    -------
    str

    Examples
    --------
    >>> print(paper_table("[Kalbe2008, Table 1]", [{"dataset": "neghip", "D2_MB": 0.77}],
    ...                   [("dataset", "dataset", "s"), ("D2 MB", "D2_MB", "f2")]), end="")
    ### paper ([Kalbe2008, Table 1])
    <BLANKLINE>
    | paper dataset | D2 MB |
    |---|---|
    | neghip | 0.77 |
    """
    cols = list(cols)
    return f"### {PAPER} ({source})\n\n" + md_table(rows, paper_columns(cols[:1]) + cols[1:])


# ---------------------------------------------------------------------------------------------- JSON
def clean(obj):
    """A copy that :func:`json.dumps` writes with ``allow_nan=False``: NaN and infinities become ``None``,
    numpy scalars plain Python numbers, tuples lists and keys strings.

    Examples
    --------
    >>> import numpy as np
    >>> clean({"n": np.int64(3), "e": [float("nan"), np.float32(0.5), np.inf], 7: (np.bool_(True), "x")})
    {'n': 3, 'e': [None, 0.5, None], '7': [True, 'x']}
    """
    if isinstance(obj, dict):
        return {str(k): clean(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [clean(v) for v in obj]
    if isinstance(obj, (np.integer,)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        return float(obj) if math.isfinite(obj) else None
    if isinstance(obj, np.bool_):
        return bool(obj)
    return obj


def write_json(path, result) -> Path:
    """Write ``clean(result)`` as indented, strictly valid JSON (no NaN) to ``path``; returns the path.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     print(write_json(Path(d) / "r.json", {"ms": [1.5, float("nan")]}).read_text())
    {
      "ms": [
        1.5,
        null
      ]
    }
    """
    path = Path(path)
    path.write_text(json.dumps(clean(result), indent=2, allow_nan=False))
    return path


# ---------------------------------------------------------------------------------------------- progress
def log(study: str, message: str) -> None:
    """One line ``[<study> study] <message>`` on stderr (flushed: it shows between progress bars).

    Examples
    --------
    >>> import contextlib, io
    >>> err = io.StringIO()
    >>> with contextlib.redirect_stderr(err):
    ...     log("volume", "cubic scheme available")
    >>> err.getvalue()
    '[volume study] cubic scheme available\\n'
    """
    print(f"[{study} study] {message}", file=sys.stderr, flush=True)


def progress_bar(iterable=None, desc: str = "", *, enabled: bool = True, **options):
    """A :mod:`tqdm` progress bar over ``iterable`` (or, with ``total=``, one updated by hand), silent when
    not ``enabled`` (the studies' ``progress=False``).

    Examples
    --------
    >>> list(progress_bar(["mesh", "spline"], "accuracy vs time", enabled=False))
    ['mesh', 'spline']
    >>> bar = progress_bar(total=2, desc="showcase", enabled=False, unit="fig")
    >>> bar.update(); bar.close(); bar.disable
    True
    """
    from tqdm import tqdm

    return tqdm(iterable, desc=desc, disable=not enabled, **options)


# ---------------------------------------------------------------------------------------------- measures
def timed(plotter, repeats: int, *, with_repeats: bool = True) -> dict:
    """Frame times of a scene as the columns of a study row, from
    :func:`splinevis.analysis.timing.frame_times` (two warm-up frames, then ``repeats`` timed ones).

    Parameters
    ----------
    plotter : splinevis.Plotter
        Anything with ``render_now()``.
    repeats : int
    with_repeats : bool, optional
        Whether the row also says how many frames were timed (key ``repeats``).

    Returns
    -------
    dict
        ``{"frame_min_ms", "frame_median_ms"[, "repeats"]}``.

    Examples
    --------
    >>> class Scene:
    ...     def render_now(self):
    ...         pass
    >>> sorted(timed(Scene(), 3))
    ['frame_median_ms', 'frame_min_ms', 'repeats']
    >>> list(timed(Scene(), 3, with_repeats=False))
    ['frame_min_ms', 'frame_median_ms']
    """
    from ..analysis.timing import frame_times

    r = frame_times(plotter, repeats)
    row = {"frame_min_ms": r["min_ms"], "frame_median_ms": r["median_ms"]}
    if with_repeats:
        row["repeats"] = r["repeats"]
    return row


def error_summary(errors, name: str, unit: str, stats=("median", "p95", "max")) -> dict:
    """Median, 95th percentile and maximum of per-pixel errors as the columns ``<name>_err_<stat>_<unit>``
    of a study row; ``None`` each when there are no errors (nothing to compare).

    Parameters
    ----------
    errors : array_like
    name : str
        What is measured, e.g. ``"normal"`` or ``"position"``.
    unit : str
        e.g. ``"deg"`` or ``"h"`` (grid spacings).
    stats : sequence of {"median", "p95", "max"}, optional

    Returns
    -------
    dict of float or None

    Examples
    --------
    >>> error_summary([0.0, 1.0, 2.0, 3.0, 4.0], "normal", "deg")
    {'normal_err_median_deg': 2.0, 'normal_err_p95_deg': 3.8, 'normal_err_max_deg': 4.0}
    >>> error_summary([], "position", "h", stats=("median", "p95"))
    {'position_err_median_h': None, 'position_err_p95_h': None}
    """
    e = np.asarray(errors, dtype=np.float64)
    measure = {"median": np.median, "p95": lambda v: np.percentile(v, 95), "max": np.max}
    return {f"{name}_err_{s}_{unit}": float(measure[s](e)) if e.size else None for s in stats}


# ---------------------------------------------------------------------------------------------- figures
def pyplot():
    """:mod:`matplotlib.pyplot` on the off-screen ``Agg`` backend (the studies run headless).

    Examples
    --------
    >>> pyplot().get_backend().lower()
    'agg'
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def save_figure(fig, path, dpi: int = 100):
    """Lay out, save and close a figure; returns ``path`` as given.

    Examples
    --------
    >>> import tempfile
    >>> fig, ax = pyplot().subplots(figsize=(2, 1))
    >>> with tempfile.TemporaryDirectory() as d:
    ...     path = save_figure(fig, Path(d) / "f.png", dpi=20)
    ...     path.name, path.stat().st_size > 0
    ('f.png', True)
    """
    fig.tight_layout()
    fig.savefig(path, dpi=dpi)
    pyplot().close(fig)
    return path
