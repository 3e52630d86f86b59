"""The report of ``splinevis check``: ``report.json`` (everything measured), ``report.md`` (a table per family
and the reasons) and ``contact_sheet.png`` (every file's thumbnail row: spline and baseline, default camera and
close-up, under its verdict).

Numbers are written as measured; times and memory depend on the machine, verdicts and accuracy figures do not.
"""

from __future__ import annotations

import json
import textwrap
from pathlib import Path

import numpy as np

__all__ = ["write_report", "summary_table"]

_COLOURS = {"PASS": "#2e7d32", "WARN": "#ef6c00", "FAIL": "#c62828", "SKIP": "#757575"}


def _fmt(x, spec=".3g"):
    return "" if x is None else format(x, spec)


def summary_table(files) -> str:
    """Markdown: files PASS / WARN / FAIL per family.

    >>> print(summary_table([{"family": "terrain", "verdict": "PASS"}, {"family": "terrain", "verdict": "FAIL"}]))
    | family | files | PASS | WARN | FAIL |
    |---|---:|---:|---:|---:|
    | terrain | 2 | 1 | 0 | 1 |
    """
    rows = ["| family | files | PASS | WARN | FAIL |", "|---|---:|---:|---:|---:|"]
    for fam in sorted({r["family"] for r in files if r.get("family")}):
        rs = [r for r in files if r.get("family") == fam]
        rows.append(f"| {fam} | {len(rs)} | " + " | ".join(str(sum(r['verdict'] == v for r in rs))
                                                          for v in ("PASS", "WARN", "FAIL")) + " |")
    return "\n".join(rows)


def _markdown(report) -> str:
    files = report["files"]
    md = ["# splinevis check", "", summary_table(files), ""]
    skipped = [r for r in files if r["verdict"] == "SKIP"]
    if skipped:
        md += ["Not judged: " + "; ".join(f"`{r['name']}` ({r['findings'][0]['reason']})" for r in skipped), ""]
    md += ["## Files", "", "| file | family | verdict | IoU default / close-up | leaks | read s | build s | 1st / 2nd frame s "
           "| peak MB |", "|---|---|---|---|---:|---:|---:|---|---:|"]
    for r in files:
        if r["verdict"] == "SKIP":
            continue
        v, t = r.get("views", {}), r.get("times", {})
        iou = " / ".join(_fmt(v[k]["iou"], ".3f") for k in ("default", "close-up") if k in v)
        leaks = sum(v[k]["leaks"] for k in v) if v else ""
        frames = " / ".join(_fmt(t.get(k), ".2f") for k in ("first_frame", "second_frame") if k in t)
        md.append(f"| `{r['name']}` | {r['family']} | **{r['verdict']}** | {iou} | {leaks} | {_fmt(t.get('read'), '.2f')} "
                  f"| {_fmt(t.get('build'), '.2f')} | {frames} | {_fmt(r.get('peak_memory_mb'), '.0f')} |")
    md += ["", "## Reasons", ""]
    for r in files:
        if r["verdict"] == "SKIP":
            continue
        md.append(f"### `{r['name']}`: {r['verdict']} ({r['family']}, baseline: {r.get('baseline', '')})")
        md.append("")
        for f in r["findings"]:
            md.append(f"- {f['level']}: {f['reason']}")
        acc = r.get("accuracy") or {}
        flat = {k: v for k, v in acc.items() if isinstance(v, (int, float)) and not isinstance(v, bool)}
        if flat:
            md.append("- accuracy: " + ", ".join(f"{k} {_fmt(v, '.4g')}" for k, v in flat.items()))
        md.append("")
    return "\n".join(md) + "\n"


def _contact_sheet(report, out: Path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from PIL import Image

    files = [r for r in report["files"] if r["verdict"] != "SKIP"]
    if not files:
        return
    fig, axes = plt.subplots(len(files), 1, figsize=(12, 2.4 * len(files)), dpi=70, squeeze=False)
    for ax, r in zip(axes[:, 0], files):
        thumb = r.get("thumbnail")
        if thumb and (out / thumb).exists():
            ax.imshow(np.asarray(Image.open(out / thumb)))
        else:
            reason = next((f["reason"] for f in r["findings"] if f["level"] == "FAIL"), "")
            text = "\n".join(textwrap.wrap("no picture: " + reason, 110)[:5])
            ax.text(0.5, 0.5, text, ha="center", va="center", fontsize=10, transform=ax.transAxes)
        ax.set_title(f"{r['name']} ({r['family']}): {r['verdict']}", loc="left", fontsize=11,
                     color=_COLOURS[r["verdict"]])
        ax.axis("off")
    fig.tight_layout()
    fig.savefig(out / "contact_sheet.png")
    plt.close(fig)


def write_report(report: dict, out) -> None:
    """Write ``report.json``, ``report.md`` and ``contact_sheet.png`` of a check into ``out``.

    >>> import tempfile, pathlib
    >>> d = pathlib.Path(tempfile.mkdtemp())
    >>> write_report({"files": [{"name": "a.obj", "family": None, "verdict": "SKIP",
    ...                          "findings": [{"level": "PASS", "reason": "not judged: empty"}]}]}, d)
    >>> sorted(p.name for p in d.iterdir())
    ['report.json', 'report.md']
    """
    out = Path(out)
    (out / "report.json").write_text(json.dumps(report, indent=1, default=float) + "\n")
    (out / "report.md").write_text(_markdown(report))
    _contact_sheet(report, out)
