#!/usr/bin/python3
"""Plots of paper_benchmark.py's results.json: time vs MSE (the paper's Fig. 2), MSE per
frame across the trajectory, and flicker per mode.

    /usr/bin/python3 Benchmarks/plot_paper.py output/paper/results.json
"""
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")  # files only, no display
import matplotlib.pyplot as plt  # noqa: E402

STYLE = {
    "classic": dict(color="#444444", marker="o"),
    "gathering reuse": dict(color="#1f77b4", marker="s"),
    "shooting reuse": dict(color="#ff7f0e", marker="^"),
    "full reuse": dict(color="#2ca02c", marker="D"),
}


def plot(results_path):
    with open(results_path) as f:
        results = json.load(f)
    folder = os.path.dirname(os.path.abspath(results_path))
    frames = results["config"]["frames"]
    middle = results["middle_frame"] + 1
    paths = results["config"]["paths"]
    written = []

    fig, ax = plt.subplots(figsize=(6.4, 4.8))
    for mode, points in results["curve"].items():
        ax.plot([p["seconds_per_frame"] for p in points], [p["mse_middle"] for p in points],
                label=mode, **STYLE[mode])
        for p in points:
            if p["paths"] == paths:
                ax.annotate(f"N={paths // 1000}k", (p["seconds_per_frame"], p["mse_middle"]),
                            textcoords="offset points", xytext=(4, 4), fontsize=7)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel(f"seconds per frame (animation of {frames} frames / {frames})")
    ax.set_ylabel(f"MSE of frame {middle} (W/m$^2$)$^2$")
    ax.set_title(f"Time vs MSE, frame {middle} of {frames} (paper Fig. 2)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    written.append(save(fig, folder, "time_vs_mse.png"))

    # The absolute MSE follows the scene's brightness as the light moves; the ratio to classic
    # shows what reuse costs: least in the middle of the trajectory, most at its ends, where
    # the mixture of positions is furthest from the frame's own importance function.
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(6.4, 7.2), sharex=True)
    classic = results["modes"]["classic"]["mse_per_frame"]
    for mode, m in results["modes"].items():
        top.plot(range(1, frames + 1), m["mse_per_frame"], label=mode, **STYLE[mode], markersize=4)
        bottom.plot(range(1, frames + 1), [a / c for a, c in zip(m["mse_per_frame"], classic)],
                    label=mode, **STYLE[mode], markersize=4)
    top.set_ylabel("MSE (W/m$^2$)$^2$")
    top.set_title(f"MSE per frame at N = {paths:,} paths per frame")
    top.set_ylim(bottom=0)
    top.grid(True, alpha=0.3)
    top.legend()
    bottom.set_xlabel("frame (light position along the diagonal)")
    bottom.set_ylabel("MSE / MSE of classic")
    bottom.grid(True, alpha=0.3)
    written.append(save(fig, folder, "mse_per_frame.png"))

    fig, ax = plt.subplots(figsize=(6.4, 4.0))
    modes = list(results["modes"])
    values = [results["modes"][m]["flicker"] for m in modes]
    bars = ax.bar(modes, values, color=[STYLE[m]["color"] for m in modes])
    ax.bar_label(bars, fmt="%.2f")
    ax.set_ylabel("flicker: RMS error of frame-to-frame change (W/m$^2$)")
    ax.set_title(f"Flicker at N = {paths:,} (lower is smoother)")
    written.append(save(fig, folder, "flicker.png"))
    return written


def save(fig, folder, name):
    path = os.path.join(folder, name)
    fig.tight_layout()
    fig.savefig(path + ".partial.png", dpi=110)
    plt.close(fig)
    os.replace(path + ".partial.png", path)
    return path


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    for path in plot(sys.argv[1]):
        print("wrote", path)
