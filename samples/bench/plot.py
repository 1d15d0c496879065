#!/usr/bin/env python3
"""glint-bench's plots, drawn with matplotlib.

glint-bench writes the points it plots as JSON beside the plot
(<plot>.plot.json) with this script (<plot>.plot.py) and runs it:

    python3 plot.py POINTS.json OUT.png OUT.svg

so a plot can be redrawn or restyled without rendering again. The JSON:
width, height (pixels of the PNG), title, xLabel, yLabel, logX, seriesLines,
paretoFront, and points: x, y, series, label, baseline (a mode's defaults),
front (on the Pareto front of time against error, computed by glint-bench).
"""
import json
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

# The modes in the colours the debug views use for their rays.
MODE_COLORS = {"hybrid": "#9632c8", "ssr": "#2f6fd6", "rt": "#d43a2f"}
DPI = 100


def main(source, png, svg):
    with open(source, encoding="utf-8") as f:
        plot = json.load(f)
    points = plot["points"]
    fig, ax = plt.subplots(figsize=(plot["width"] / DPI, plot["height"] / DPI), dpi=DPI)

    series = []
    for p in points:
        if p["series"] not in series:
            series.append(p["series"])
    for index, name in enumerate(series):
        mine = [p for p in points if p["series"] == name]
        color = MODE_COLORS.get(name, f"C{index}")
        if plot["seriesLines"]:
            line = sorted(mine, key=lambda p: p["x"])
            ax.plot([p["x"] for p in line], [p["y"] for p in line], color=color, linewidth=1.2, zorder=2)
        swept = [p for p in mine if not p["baseline"]]
        if swept:
            ax.scatter([p["x"] for p in swept], [p["y"] for p in swept], s=16, color=color, label=name, zorder=3)
        defaults = [p for p in mine if p["baseline"]]
        ax.scatter([p["x"] for p in defaults], [p["y"] for p in defaults], s=70, marker="D", color=color,
                   edgecolors="black", linewidths=0.8, zorder=4,
                   label=None if swept else name)

    if plot["paretoFront"]:
        front = sorted((p for p in points if p["front"]), key=lambda p: p["x"])
        if front:
            ax.plot([p["x"] for p in front], [p["y"] for p in front], color="black", linestyle="--",
                    linewidth=1.0, label="Pareto front", zorder=1)
            for p in front:
                if p["label"]:
                    ax.annotate(p["label"], (p["x"], p["y"]), textcoords="offset points", xytext=(5, 4),
                                fontsize=7)
    if any(p["baseline"] for p in points):
        ax.scatter([], [], s=70, marker="D", color="white", edgecolors="black", label="mode defaults")

    if plot["logX"]:
        ax.set_xscale("log")
    ax.set_title(plot["title"], fontsize=9)
    ax.set_xlabel(plot["xLabel"], fontsize=8)
    ax.set_ylabel(plot["yLabel"], fontsize=8)
    ax.tick_params(labelsize=7)
    ax.grid(True, color="#dddddd", linewidth=0.6)
    if points:
        ax.legend(fontsize=7, loc="best")
    fig.tight_layout()
    fig.savefig(png, dpi=DPI)
    fig.savefig(svg)


if __name__ == "__main__":
    if len(sys.argv) != 4:
        sys.exit("usage: plot.py POINTS.json OUT.png OUT.svg")
    main(sys.argv[1], sys.argv[2], sys.argv[3])
