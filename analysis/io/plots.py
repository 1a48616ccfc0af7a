"""Plots of silo discharge (PNG, matplotlib Agg backend, no display needed)."""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING

import matplotlib

matplotlib.use("Agg")  # headless: runs on clusters and in CI

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from analysis.io.tables import atomic_output  # noqa: E402

if TYPE_CHECKING:
    from analysis.numerics.flow import DischargeHistory, FlowRateFit

__all__ = ["plot_discharge"]


def save_png(figure, path: str | os.PathLike, tight: bool = False) -> Path:
    """Save a figure as a 150 dpi PNG, atomically: a reader never sees a half-written file."""
    with atomic_output(path) as temporary:
        # The temporary name has no .png suffix, so give the format explicitly.
        figure.savefig(temporary, dpi=150, format="png", bbox_inches="tight" if tight else None)
    return Path(path)


def plot_discharge(
    history: "DischargeHistory",
    fit: "FlowRateFit",
    beverloo_rate: float | None,
    path: str | os.PathLike,
    title: str,
) -> Path:
    """Plot discharged mass against time with the fitted and Beverloo flow rates.

    Draws the discharged mass, the least-squares line over the steady window
    (shaded), and, for comparison, a line of the Beverloo slope through the
    fitted line at the window midpoint (so only the slopes are compared).

    Parameters
    ----------
    history : analysis.numerics.flow.DischargeHistory
        Time since opening [s] and discharged mass [kg].
    fit : analysis.numerics.flow.FlowRateFit
        Steady flow rate fit [kg/s] and its window [s].
    beverloo_rate : float or None
        Beverloo mass flow rate [kg/s]; None to omit the line.
    path : str or os.PathLike
        Destination PNG file (written atomically, 150 dpi).
    title : str
        Figure title.

    Returns
    -------
    pathlib.Path
        The written path.
    """
    time = np.asarray(history.time, dtype=float)
    mass = np.asarray(history.discharged_mass, dtype=float)

    figure, axes = plt.subplots(figsize=(6.4, 4.4))
    try:
        axes.plot(time, mass, ".", markersize=3, color="0.35", label="DEM discharged mass")
        axes.axvspan(fit.t_start, fit.t_end, color="tab:blue", alpha=0.08, label="steady window")

        window_time = np.array([fit.t_start, fit.t_end])
        axes.plot(
            window_time,
            fit.intercept + fit.mass_flow_rate * window_time,
            "-",
            color="tab:blue",
            linewidth=2,
            label=f"fit: {fit.mass_flow_rate:.4g} ± {fit.standard_error:.2g} kg/s",
        )
        if beverloo_rate is not None:
            midpoint_time = 0.5 * (fit.t_start + fit.t_end)
            midpoint_mass = fit.intercept + fit.mass_flow_rate * midpoint_time
            axes.plot(
                window_time,
                midpoint_mass + beverloo_rate * (window_time - midpoint_time),
                "--",
                color="tab:red",
                linewidth=1.5,
                label=f"Beverloo: {beverloo_rate:.4g} kg/s",
            )

        axes.set_xlabel("time since opening [s]")
        axes.set_ylabel("discharged mass [kg]")
        axes.set_title(title)
        axes.grid(True, alpha=0.3)
        axes.legend(loc="upper left", fontsize="small")
        figure.tight_layout()
        return save_png(figure, path)
    finally:
        plt.close(figure)
