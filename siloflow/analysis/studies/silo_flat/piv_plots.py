"""The synthetic PIV study's plot: PIV's error of the vertical velocity against image resolution, one line per
camera frame rate, with the spread over the frame pairs as error bars."""

from __future__ import annotations

import os
from pathlib import Path

import matplotlib
import numpy as np
from matplotlib.figure import Figure

from siloflow.analysis.io.plots import save_figure

__all__ = ["plot_piv_accuracy"]


def plot_piv_accuracy(rows: list[dict], path: str | os.PathLike, title: str = "Synthetic PIV of the front wall") -> Path:
    """PIV's errors against the pixel size [mm/px] (rows of :func:`siloflow.analysis.piv.accuracy.accuracy_table`), one line
    per frame rate: the RMS error (error bars: spread over the frame pairs) and bias of v_z and the centreline error
    [m/s], the flow channel boundary's error [mm] and the kinematic constant's [%]; combinations without a valid
    vector are left out."""
    if not rows:
        raise ValueError("no PIV accuracy rows to plot")
    figure = Figure(figsize=(13.0, 4.2))
    velocity, boundary, constant = figure.subplots(1, 3)

    def finite(value) -> float:
        return float(value) if value is not None and np.isfinite(value) else float("nan")

    for rate in sorted({row["frame_rate_hz"] for row in rows}):
        chosen = sorted((r for r in rows if r["frame_rate_hz"] == rate and np.isfinite(finite(r["rms_w_m_s"]))),
                        key=lambda r: r["mm_per_px"])
        if not chosen:
            continue
        size = [r["mm_per_px"] for r in chosen]
        spread = [finite(r["rms_w_spread_m_s"]) if np.isfinite(finite(r["rms_w_spread_m_s"])) else 0.0 for r in chosen]
        velocity.errorbar(size, [r["rms_w_m_s"] for r in chosen], yerr=spread, marker="o", capsize=3,
                          label=f"RMS, {rate:g} frames/s")
        velocity.plot(size, [abs(r["bias_w_m_s"]) for r in chosen], linestyle="--", marker="x",
                      label=f"|bias|, {rate:g} frames/s")
        velocity.plot(size, [abs(finite(r.get("centreline_w_error_m_s"))) for r in chosen], linestyle=":",
                      marker="s", label=f"|centreline error|, {rate:g} frames/s")
        boundary.plot(size, [1e3 * finite(r.get("fcb_error_m")) for r in chosen], marker="o", label=f"{rate:g} frames/s")
        constant.plot(size, [finite(r.get("kinematic_b_error_percent")) for r in chosen], marker="o",
                      label=f"{rate:g} frames/s")
    velocity.set_ylabel("error of v_z (m/s)")
    boundary.set_ylabel("flow channel boundary error (mm)")
    constant.set_ylabel("error of the kinematic constant B (%)")
    constant.axhline(0.0, color="grey", linewidth=0.8)
    for axes in (velocity, boundary, constant):
        axes.set_xlabel("pixel size (mm/px)")
        axes.grid(alpha=0.3)
        axes.legend(fontsize="x-small")
    figure.suptitle(title)
    return save_figure(figure, path, tight=True)


def plot_piv_comparison(pairs, path: str | os.PathLike, title: str = "DEM front wall vs measured PIV") -> Path:
    """DEM and measured v_z profiles side by side (pairs of :func:`siloflow.analysis.piv.compare.profile_pairs`): one panel per
    height, one colour per time window; the DEM as a line with its standard error, the measurement as points with
    the PIV error band of the synthetic study shaded about them."""
    if not pairs:
        raise ValueError("no profile pairs to plot")
    heights = sorted({pair.z for pair in pairs})
    windows = sorted({pair.window for pair in pairs})
    figure = Figure(figsize=(3.2 * len(heights) + 0.8, 3.8))
    panels = figure.subplots(1, len(heights), sharey=True, squeeze=False)[0]
    colours = matplotlib.colormaps["tab10"]
    for pair in pairs:
        axes = panels[heights.index(pair.z)]
        colour = colours(windows.index(pair.window) % 10)
        label = f"{pair.window[0]:g}-{pair.window[1]:g} s"
        x = 1e3 * pair.x
        error = np.where(np.isfinite(pair.dem_error), pair.dem_error, 0.0)
        axes.errorbar(x, pair.dem_w, yerr=error, color=colour, capsize=2, label=f"DEM, {label}")
        axes.plot(x, pair.measured_w, "o", color=colour, markerfacecolor="none", label=f"PIV, {label}")
        if np.isfinite(pair.band):
            axes.fill_between(x, pair.measured_w - pair.band, pair.measured_w + pair.band, color=colour, alpha=0.2,
                              linewidth=0)
        axes.set_title(f"z = {1e3 * pair.z:.0f} mm")
        axes.set_xlabel("x (mm)")
        axes.grid(alpha=0.3)
    panels[0].set_ylabel("v_z (m/s)")
    panels[0].legend(fontsize="x-small")
    figure.suptitle(title)
    return save_figure(figure, path, tight=True)
