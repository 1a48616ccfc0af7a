"""The synthetic PIV study's plot: PIV's error of the vertical velocity against image resolution, one line per
camera frame rate, with the spread over the frame pairs as error bars."""

from __future__ import annotations

import os
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # headless: runs on clusters and in CI

import numpy as np  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

from analysis.io.plots import save_png  # noqa: E402

__all__ = ["plot_piv_accuracy"]


def plot_piv_accuracy(rows: list[dict], path: str | os.PathLike, title: str = "Synthetic PIV of the front wall") -> Path:
    """RMS error and bias of v_z [m/s] against the pixel size [mm/px] (rows of
    :func:`analysis.piv.accuracy.accuracy_table`); combinations without a valid vector are left out."""
    if not rows:
        raise ValueError("no PIV accuracy rows to plot")
    figure = Figure(figsize=(6.4, 4.2))
    axes = figure.add_subplot()
    for rate in sorted({row["frame_rate_hz"] for row in rows}):
        chosen = sorted((r for r in rows if r["frame_rate_hz"] == rate and np.isfinite(r["rms_w_m_s"])),
                        key=lambda r: r["mm_per_px"])
        if not chosen:
            continue
        size = [r["mm_per_px"] for r in chosen]
        spread = [r["rms_w_spread_m_s"] if np.isfinite(r["rms_w_spread_m_s"]) else 0.0 for r in chosen]
        axes.errorbar(size, [r["rms_w_m_s"] for r in chosen], yerr=spread, marker="o", capsize=3,
                      label=f"RMS, {rate:g} frames/s")
        axes.plot(size, [abs(r["bias_w_m_s"]) for r in chosen], linestyle="--", marker="x",
                  label=f"|bias|, {rate:g} frames/s")
    axes.set_xlabel("pixel size (mm/px)")
    axes.set_ylabel("error of v_z (m/s)")
    axes.set_title(title)
    axes.legend(fontsize="small")
    axes.grid(alpha=0.3)
    return save_png(figure, path, tight=True)
