"""The HTML report of ``--metrics``: what each process of the run cost, and over time.

One self-contained file (no script, no network): a table per process (samples, CPU seconds,
mean and peak CPU, peak memory, threads and open files) and two plots drawn as inline SVG, CPU
and memory over the run. Long runs are thinned to at most MAX_POINTS points per line.
"""

from __future__ import annotations

import html
import os
from collections.abc import Sequence

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING
if TYPE_CHECKING:
    from mlaunch.parts.usage import Sample

MAX_POINTS = 600
WIDTH, HEIGHT = 900, 220
COLOURS = ("#4e79a7", "#f28e2b", "#e15759", "#76b7b2", "#59a14f", "#edc948", "#b07aa1", "#9c755f")


def report_path(csv_path: str) -> str:
    """``run.csv`` -> ``run.html`` (any other name gets ``.html`` added)."""
    root, ext = os.path.splitext(csv_path)
    return (root if ext.lower() == ".csv" else csv_path) + ".html"


class _Series:
    """One label's samples: (elapsed, cpu percent, rss bytes, threads, files)."""

    def __init__(self) -> None:
        self.points: list[tuple[float, float, int, int, int]] = []

    def cpu_seconds(self) -> float:
        total, previous = 0.0, None
        for t, cpu, *_ in self.points:
            if previous is not None:
                total += cpu / 100.0 * (t - previous)
            previous = t
        return total


def _series(samples: Sequence[Sample]) -> dict[str, _Series]:
    series: dict[str, _Series] = {}
    for sample in samples:
        for info, usage in sample.rows:
            if usage is None:
                continue
            point = (sample.elapsed, usage.cpu, usage.rss, usage.threads, usage.files)
            series.setdefault(info.label, _Series()).points.append(point)
    return series


def write_report(path: str, samples: Sequence[Sample]) -> None:
    """Write the report of ``samples`` to ``path``."""
    with open(path, "w", encoding="utf-8") as f:
        f.write(render(samples))


def render(samples: Sequence[Sample]) -> str:
    series = _series(samples)
    duration = samples[-1].elapsed if samples else 0.0
    rows = []
    for label, s in series.items():
        cpus = [p[1] for p in s.points]
        cells = (
            html.escape(label),
            str(len(s.points)),
            f"{s.cpu_seconds():.1f}",
            f"{sum(cpus) / len(cpus):.1f}",
            f"{max(cpus):.1f}",
            f"{max(p[2] for p in s.points) / 2**20:.1f}",
            str(max(p[3] for p in s.points)),
            str(max(p[4] for p in s.points)),
        )
        rows.append("<tr>" + "".join(f"<td>{c}</td>" for c in cells) + "</tr>\n")
    total_cpu = sum(s.cpu_seconds() for s in series.values())
    peak_rss = sum(max(p[2] for p in s.points) for s in series.values()) / 2**20
    rows.append(
        f"<tr><th>all</th><td></td><td>{total_cpu:.1f}</td><td></td><td></td>"
        f"<td>{peak_rss:.1f}</td><td></td><td></td></tr>\n"
    )
    cpu_plot = _plot(series, 1, 1.0, "CPU (% of one core)")
    rss_plot = _plot(series, 2, 1 / 2**20, "memory (RSS, MiB)")
    legend = "".join(
        f'<span style="color:{COLOURS[i % len(COLOURS)]}">&#9632; {html.escape(label)}</span> '
        for i, label in enumerate(series)
    )
    return f"""<!doctype html>
<html><head><meta charset="utf-8"><title>mlaunch metrics</title>
<style>
body {{ font: 14px sans-serif; margin: 1.5em; color: #222; }}
table {{ border-collapse: collapse; }}
td, th {{ padding: 2px 10px; border-bottom: 1px solid #ddd; }}
td:not(:first-child), th:not(:first-child) {{ text-align: right; }}
svg {{ background: #fafafa; border: 1px solid #ddd; margin: 0.5em 0; }}
</style></head><body>
<h1>What the run cost</h1>
<p>{len(samples)} samples over {duration:.0f} s, one a second.</p>
<table><tr><th>process</th><th>samples</th><th>CPU seconds</th><th>mean CPU %</th>
<th>peak CPU %</th><th>peak RSS MiB</th><th>peak threads</th><th>peak open files</th></tr>
{"".join(rows)}
</table>
<h2>CPU</h2>{cpu_plot}
<h2>Memory</h2>{rss_plot}
<p>{legend}</p>
</body></html>
"""


def _plot(series: dict[str, _Series], column: int, scale: float, title: str) -> str:
    """An SVG line plot of ``column`` of every series (times ``scale``) against elapsed time."""
    end = max((s.points[-1][0] for s in series.values() if s.points), default=0.0) or 1.0
    top = max((p[column] * scale for s in series.values() for p in s.points), default=0.0)
    top = top * 1.1 or 1.0
    pad = 40
    lines = []
    for i, s in enumerate(series.values()):
        step = max(1, len(s.points) // MAX_POINTS)
        points = " ".join(
            f"{pad + p[0] / end * (WIDTH - pad - 10):.1f},"
            f"{HEIGHT - 20 - p[column] * scale / top * (HEIGHT - 30):.1f}"
            for p in s.points[::step]
        )
        colour = COLOURS[i % len(COLOURS)]
        lines.append(
            f'<polyline fill="none" stroke="{colour}" stroke-width="1.5" points="{points}"/>'
        )
    axes = (
        f'<line x1="{pad}" y1="{HEIGHT - 20}" x2="{WIDTH - 10}" y2="{HEIGHT - 20}" stroke="#888"/>'
        f'<text x="2" y="14" font-size="11">{top:.0f}</text>'
        f'<text x="2" y="{HEIGHT - 22}" font-size="11">0</text>'
        f'<text x="{WIDTH - 60}" y="{HEIGHT - 4}" font-size="11">{end:.0f} s</text>'
        f'<text x="{pad + 4}" y="14" font-size="12">{html.escape(title)}</text>'
    )
    return f'<svg width="{WIDTH}" height="{HEIGHT}" role="img">{axes}{"".join(lines)}</svg>'
