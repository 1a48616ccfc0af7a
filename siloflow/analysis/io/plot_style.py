"""One plotting style for the report and the validation record: figures a journal would print as they are.

Importing this module changes nothing in matplotlib (no global ``rcParams``, no backend): a writer draws under
:func:`journal_style`, which applies :data:`STYLE` with :func:`matplotlib.rc_context` and puts every setting back on
leaving. The constants are for what a writer chooses per series: :data:`PALETTE` (one colour per flow pattern, insert
or shape, given by :func:`colour_of`), :data:`LINE_STYLES` and :data:`MARKERS` (one per layout or variant). A legend
goes outside the data with :func:`legend_outside`.

Sizes are chosen for a figure printed at the text width of a page, :data:`PAGE_WIDTH` = 6.5 in (a letter or A4 page
with 1 in margins): axis labels 9 pt and tick labels and legends 8 pt, the figure text a journal asks for at print
width (typically 8-9 pt, never below 6-7 pt), so a figure drawn at that width needs no rescaling to be read.
"""

from __future__ import annotations

from collections.abc import Iterable
from contextlib import contextmanager

import matplotlib
from matplotlib import cycler

__all__ = [
    "PAGE_WIDTH",
    "LABEL_SIZE",
    "TICK_SIZE",
    "LEGEND_SIZE",
    "LINE_WIDTH",
    "MARKER_SIZE",
    "PALETTE",
    "LINE_STYLES",
    "MARKERS",
    "STYLE",
    "journal_style",
    "legend_outside",
    "colour_of",
]

#: Width of a figure printed across the text of a page [in]: 8.5 in letter (or 8.27 in A4) less two 1 in margins.
PAGE_WIDTH = 6.5
#: Font size of the axis labels and titles [pt]: a journal's figure text at print width is 8-9 pt.
LABEL_SIZE = 9
#: Font size of the tick labels [pt]: one step below the labels they number, still readable in print.
TICK_SIZE = 8
#: Font size of the legend [pt]: as the ticks, so that a legend does not outweigh the data.
LEGEND_SIZE = 8
#: Width of a data line [pt]: heavy enough to tell its colour and dash pattern at print size, light enough that
#: crossing lines stay apart.
LINE_WIDTH = 1.3
#: Size of a data marker [pt]: visible at print size without hiding the line's course between points.
MARKER_SIZE = 4.5
#: The Okabe-Ito palette (Okabe & Ito 2008, "Color universal design"): black, orange, sky blue, bluish green, yellow,
#: blue, vermillion and reddish purple. Its eight colours stay distinguishable under the common colour-vision
#: deficiencies (protanopia, deuteranopia, tritanopia) and in greyscale print by their lightness.
PALETTE = ("#000000", "#E69F00", "#56B4E9", "#009E73", "#F0E442", "#0072B2", "#D55E00", "#CC79A7")
#: Line styles of the variants (layouts) of one colour: solid, dashed, dash-dot, dotted; a reader who cannot tell
#: two colours apart still tells the variants apart.
LINE_STYLES = ("-", "--", "-.", ":")
#: Markers of the variants, in the same order as :data:`LINE_STYLES`: distinct shapes, all filled.
MARKERS = ("o", "s", "^", "D", "v", "P")
#: The rcParams :func:`journal_style` applies (the fonts embedded in a PDF are set by
#: :func:`siloflow.analysis.io.plots.save_figure`, for every plot).
STYLE = {
    "font.size": LABEL_SIZE,
    "axes.labelsize": LABEL_SIZE,
    "axes.titlesize": LABEL_SIZE,
    "xtick.labelsize": TICK_SIZE,
    "ytick.labelsize": TICK_SIZE,
    "legend.fontsize": LEGEND_SIZE,
    "legend.title_fontsize": LEGEND_SIZE,
    "figure.titlesize": LABEL_SIZE,
    "lines.linewidth": LINE_WIDTH,
    "lines.markersize": MARKER_SIZE,
    "axes.linewidth": 0.8,
    "axes.prop_cycle": cycler(color=PALETTE),
    # a legend frame drawn outside the data only adds ink
    "legend.frameon": False,
}


@contextmanager
def journal_style():
    """Draw under the project's style (:data:`STYLE`); every rcParam is restored on leaving.

    Create the figure, draw and save inside the ``with`` block: font sizes and line widths are read when an artist
    is made.

    Yields
    ------
    None

    Examples
    --------
    >>> import matplotlib.pyplot as plt
    >>> with journal_style():
    ...     figure, axes = plt.subplots(figsize=(PAGE_WIDTH, 3.5))
    """
    with matplotlib.rc_context(STYLE):
        yield


def legend_outside(axes, **kwargs):
    """The legend of ``axes`` to the right of the axes, outside the data area, aligned with the axes' top.

    A legend inside the axes covers data wherever the data happen to be; outside it never does. Save the figure
    with a tight bounding box (``save_figure(..., tight=True)``) or leave room on the right so that it is kept.

    Parameters
    ----------
    axes : matplotlib.axes.Axes
        The axes whose legend this is.
    **kwargs
        Passed to :meth:`matplotlib.axes.Axes.legend` (e.g. ``handles``); they override the placement defaults
        ``loc="upper left"``, ``bbox_to_anchor=(1.02, 1.0)`` (just right of the axes, in axes coordinates) and
        ``borderaxespad=0``.

    Returns
    -------
    matplotlib.legend.Legend
        The legend.
    """
    placement = {"loc": "upper left", "bbox_to_anchor": (1.02, 1.0), "borderaxespad": 0.0}
    return axes.legend(**{**placement, **kwargs})


def colour_of(names: Iterable[str]) -> dict[str, str]:
    """One colour of :data:`PALETTE` per name, in the order the names first appear.

    The same names in the same order always get the same colours, so that a flow pattern keeps its colour in
    every figure drawn from the same list; a repeated name keeps the colour of its first appearance.

    Parameters
    ----------
    names : iterable of str
        The series' names (flow patterns, inserts, shapes).

    Returns
    -------
    dict of str to str
        Name -> hex colour, in the names' order; all colours distinct.

    Raises
    ------
    ValueError
        When there are more distinct names than colours in :data:`PALETTE` (8): a colour would then stand for two
        series.
    """
    distinct = list(dict.fromkeys(str(name) for name in names))
    if len(distinct) > len(PALETTE):
        raise ValueError(f"names: {len(distinct)} distinct names, but the palette has {len(PALETTE)} colours; "
                         "draw the others with line styles or in another figure")
    return dict(zip(distinct, PALETTE))
