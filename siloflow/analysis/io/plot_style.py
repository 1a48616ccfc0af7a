"""One plotting style for the report and the validation record: figures a journal would print as they are.

Importing this module changes nothing in matplotlib (no global ``rcParams``, no backend): a writer draws under
:func:`journal_style`, which applies :data:`STYLE` with :func:`matplotlib.rc_context` and puts every setting back on
leaving. The constants are for what a writer chooses per series: :data:`PALETTE` (one colour per flow pattern, insert
or shape, given by :func:`colour_of`), :data:`LINE_STYLES` and :data:`MARKERS` (one per layout or variant). A legend
goes outside the data with :func:`legend_outside`.

The study's findings are drawn beside a result in one way in every figure: a number the study states
(:class:`StudyValue`) as a dotted line with its band (:func:`draw_study_value`, from :func:`draw_reference_value` and
:func:`draw_reference_band`), a finding stated in words (:class:`StudyNote`: a trend, an order) as an entry of the
legend (:func:`note_study`); each labelled ``study (<id>): ...`` (:func:`study_label`), so that a reader finds it in
the validation record by its id.

Sizes are chosen for a figure printed at the text width of a page, :data:`PAGE_WIDTH` = 6.5 in (a letter or A4 page
with 1 in margins): axis labels 9 pt and tick labels and legends 8 pt, the figure text a journal asks for at print
width (typically 8-9 pt, never below 6-7 pt), so a figure drawn at that width needs no rescaling to be read.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
from contextlib import contextmanager
from dataclasses import dataclass

import matplotlib
from matplotlib import cycler
from matplotlib.lines import Line2D

from siloflow.model.checks import finite_number


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
    "REFERENCE_COLOUR",
    "BAND_ALPHA",
    "journal_style",
    "legend_outside",
    "colour_of",
    "study_label",
    "StudyValue",
    "StudyNote",
    "study_findings",
    "draw_reference_value",
    "draw_reference_band",
    "draw_study_value",
    "note_study",
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
#: Colour of a reference that belongs to no one series (a measured target, a finding of the whole figure): a grey
#: that stays behind the palette's colours in print.
REFERENCE_COLOUR = "0.35"
#: Opacity of a reference band: light enough that the data drawn over it keep their colour.
BAND_ALPHA = 0.15


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


def legend_outside(axes, clear_of: Sequence = (), **kwargs):
    """The legend of ``axes`` to the right of the axes, outside the data area, aligned with the axes' top.

    A legend inside the axes covers data wherever the data happen to be; outside it never does. Save the figure
    with a tight bounding box (``save_figure(..., tight=True)``) or leave room on the right so that it is kept.

    Parameters
    ----------
    axes : matplotlib.axes.Axes
        The axes whose legend this is.
    clear_of : sequence of matplotlib.artist.Artist, optional
        Artists right of the axes that the legend must not cover (e.g. a secondary y axis with its tick labels and
        label): the legend then stands right of the rightmost of them. Its place is measured on the figure as laid
        out now, so place the legend after the figure's layout (``subplots_adjust``) is set.
    **kwargs
        Passed to :meth:`matplotlib.axes.Axes.legend` (e.g. ``handles``); they override the placement defaults
        ``loc="upper left"``, ``bbox_to_anchor=(1.02, 1.0)`` (just right of the axes, or of ``clear_of``, in axes
        coordinates) and ``borderaxespad=0``.

    Returns
    -------
    matplotlib.legend.Legend
        The legend.
    """
    left = 1.0
    if clear_of:
        # tick labels take their text and size only when drawn: lay the figure out once (the whole figure, the
        # canvas', should the axes be in a subfigure), then measure
        axes.figure.canvas.figure.draw_without_rendering()
        right = max(artist.get_tightbbox().x1 for artist in clear_of)
        left = max(left, float(axes.transAxes.inverted().transform((right, 0.0))[0]))
    placement = {"loc": "upper left", "bbox_to_anchor": (left + 0.02, 1.0), "borderaxespad": 0.0}
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


def study_label(finding_id: str, text: str) -> str:
    """The label of a finding of the study drawn in a figure: ``study (<id>): <text>``, e.g. ``study (C2): ~0.54``.

    Parameters
    ----------
    finding_id : str
        The finding's id in the study's list (:data:`siloflow.analysis.studies.validation.findings.BY_ID`).
    text : str
        What the finding states, as short as the legend allows.

    Returns
    -------
    str
        The label.
    """
    return f"study ({finding_id}): {text}"


def _finding_id(name: str, value) -> str:
    if not isinstance(value, str) or not value:
        raise ValueError(f"{name} must be a non-empty finding id such as 'C2', got {value!r}")
    return value


@dataclass(frozen=True)
class StudyValue:
    """A number the study states, to draw beside the result it is compared with (:func:`draw_study_value`).

    Attributes
    ----------
    id : str
        The finding's id (``"C2"``), shown in the label.
    value : float
        The number, in ``unit``.
    unit : str, optional
        Its unit (``"-"`` for a dimensionless one, the default): the figure says in which of its units it takes
        a value (e.g. the calibration chart a bulk friction coefficient ``"-"`` or an angle ``"deg"``).
    band : tuple of float, optional
        ``(low, high)`` in ``unit``: the band the figure's value is judged in (e.g.
        :func:`siloflow.analysis.studies.validation.agreement.study_band`); None: the value alone.
    series : str, optional
        The series it belongs to (a shape, a passage, a flow pattern): it takes that series' colour and its name
        goes into the label. None: the figure's as a whole, in :data:`REFERENCE_COLOUR`.
    approximate : bool, optional
        The study says "about" it: the label reads ``~0.54``.

    Raises
    ------
    ValueError
        For an empty id, a non-finite value or band end, or ``band`` not ``(low, high)`` with ``low <= high``.
    """

    id: str
    value: float
    unit: str = "-"
    band: tuple[float, float] | None = None
    series: str | None = None
    approximate: bool = True

    def __post_init__(self):
        _finding_id("id", self.id)
        object.__setattr__(self, "value", finite_number(f"{self.id}: value", self.value))
        if self.band is not None:
            band = tuple(self.band)
            if len(band) != 2:
                raise ValueError(f"{self.id}: band must be (low, high), got {self.band!r}")
            low, high = (finite_number(f"{self.id}: band", end) for end in band)
            if high < low:
                raise ValueError(f"{self.id}: band must be (low, high) with low <= high, got {self.band!r}")
            object.__setattr__(self, "band", (low, high))

    @property
    def label(self) -> str:
        """``study (<id>): [series ]~<value>[ unit]``, e.g. ``study (C2): ~0.54`` or ``study (C7): ~30 deg``."""
        series = f"{self.series} " if self.series else ""
        unit = "" if self.unit in ("", "-") else f" {self.unit}"
        return study_label(self.id, f"{series}{'~' if self.approximate else ''}{self.value:g}{unit}")


@dataclass(frozen=True)
class StudyNote:
    """A finding of the study stated in words (a trend, an order), to draw beside the result it is compared with.

    Attributes
    ----------
    id : str
        The finding's id (``"S5"``), shown in the label.
    text : str
        What it states, e.g. ``"B decreases with height"``.

    Raises
    ------
    ValueError
        For an empty id or text.
    """

    id: str
    text: str

    def __post_init__(self):
        _finding_id("id", self.id)
        if not isinstance(self.text, str) or not self.text:
            raise ValueError(f"{self.id}: text must be a non-empty string, got {self.text!r}")

    @property
    def label(self) -> str:
        """``study (<id>): <text>``, e.g. ``study (S5): B decreases with height``."""
        return study_label(self.id, self.text)


def study_findings(findings, *kinds: type) -> list:
    """The findings a figure is asked to draw, as a list, each of one of the types it draws.

    Parameters
    ----------
    findings : sequence of StudyValue or StudyNote, or None
        As the figure's ``findings`` argument; None: none.
    *kinds : type
        The types the figure draws (:class:`StudyValue`, :class:`StudyNote`).

    Returns
    -------
    list
        The findings, in their order.

    Raises
    ------
    ValueError
        Naming ``findings[i]`` when it is of none of ``kinds``.
    """
    checked = list(findings or ())
    for i, item in enumerate(checked):
        if not isinstance(item, kinds):
            raise ValueError(f"findings[{i}] must be a {' or '.join(kind.__name__ for kind in kinds)}, got "
                             f"{type(item).__name__}")
    return checked


def draw_reference_value(axes, value: float, label: str | None = None, *, colour=REFERENCE_COLOUR,
                         linestyle: str = ":", vertical: bool = False, gid: str | None = None):
    """A reference value drawn once across the whole axes: a line at y = ``value`` (x = ``value`` if ``vertical``).

    Thinner than a data line (1.0 pt against :data:`LINE_WIDTH`) and dotted by default, so that it reads as a
    reference and not as one more series.

    Parameters
    ----------
    axes : matplotlib.axes.Axes
        The axes.
    value : float
        Where the line stands, in the axis' data units (e.g. deg, m/s).
    label : str, optional
        Its legend entry (e.g. :func:`study_label`); None: none.
    colour : color, optional
        Its colour: a series' colour when it belongs to one, else :data:`REFERENCE_COLOUR`.
    linestyle : str, optional
        Its dash pattern.
    vertical : bool, optional
        Draw a vertical line at x = ``value`` instead.
    gid : str, optional
        Its group id, for the tests and for a reader of an SVG (e.g. ``"finding C2"``).

    Returns
    -------
    matplotlib.lines.Line2D
        The line.
    """
    draw = axes.axvline if vertical else axes.axhline
    return draw(value, color=colour, linestyle=linestyle, linewidth=1.0, label=label or "_nolegend_", gid=gid)


def draw_reference_band(axes, low: float, high: float, label: str | None = None, *, colour=REFERENCE_COLOUR,
                        vertical: bool = False, gid: str | None = None):
    """A reference band drawn once across the whole axes: y from ``low`` to ``high`` (x if ``vertical``), shaded
    with :data:`BAND_ALPHA` behind the data.

    Parameters
    ----------
    axes : matplotlib.axes.Axes
        The axes.
    low, high : float
        The band's ends, in the axis' data units (e.g. deg, m/s).
    label : str, optional
        Its legend entry; None: none (a band drawn with its value line is named by the line).
    colour : color, optional
        Its colour: a series' colour when it belongs to one, else :data:`REFERENCE_COLOUR`.
    vertical : bool, optional
        Shade x from ``low`` to ``high`` instead.
    gid : str, optional
        Its group id (e.g. ``"finding C2"``).

    Returns
    -------
    matplotlib.patches.Rectangle
        The band.
    """
    draw = axes.axvspan if vertical else axes.axhspan
    return draw(low, high, color=colour, alpha=BAND_ALPHA, linewidth=0.0, label=label or "_nolegend_", gid=gid,
                zorder=0.5)


def draw_study_value(axes, study: StudyValue, *, colour=REFERENCE_COLOUR,
                     convert: Callable[[float], float] | None = None, vertical: bool = False,
                     spans: Sequence[tuple[float, float]] = (), label: str | None = None) -> list:
    """A number the study states, drawn once: its band (if any) shaded and a dotted line at the value, all with
    ``gid="finding <id>"``; the first line carries the legend entry.

    Parameters
    ----------
    axes : matplotlib.axes.Axes
        The axes.
    study : StudyValue
        The number (and band) in the study's unit.
    colour : color, optional
        The colour of the series it belongs to; :data:`REFERENCE_COLOUR` for the figure's as a whole.
    convert : callable, optional
        Maps a number in the study's unit to the axis' data unit (e.g. a friction coefficient [-] to its angle
        [deg], a velocity ratio [-] to a velocity [m/s]); increasing or decreasing. None: the same unit.
    vertical : bool, optional
        Draw at x instead of y, across the whole axes (not with ``spans``).
    spans : sequence of (float, float), optional
        Draw over these x ranges only [x data units] (e.g. the two halves of a passage), one segment each,
        instead of across the whole axes.
    label : str, optional
        The legend entry; None: :attr:`StudyValue.label`.

    Returns
    -------
    list of matplotlib.artist.Artist
        The band(s) (if drawn), then the line(s); the last is the line that carries the legend entry.
    """
    convert = convert or float
    gid, label = f"finding {study.id}", study.label if label is None else label
    value = convert(study.value)
    band = None if study.band is None else (convert(study.band[0]), convert(study.band[1]))
    if not spans:
        bands = [] if band is None else [draw_reference_band(axes, *band, colour=colour, vertical=vertical, gid=gid)]
        return bands + [draw_reference_value(axes, value, label, colour=colour, vertical=vertical, gid=gid)]
    bands, lines = [], []
    for k, (low, high) in enumerate(spans):
        if band is not None:
            bands.append(axes.fill_between([low, high], *band, color=colour, alpha=BAND_ALPHA, linewidth=0.0,
                                           label="_nolegend_", gid=gid))
        lines += axes.plot([low, high], [value, value], ":", color=colour, linewidth=1.5, gid=gid,
                           label=label if k == 0 else "_nolegend_")
    # the legend's handle is the first line: put it last, where a caller takes it
    return bands + lines[1:] + lines[:1]


def note_study(axes, note: StudyNote):
    """A finding stated in words, as an entry of the legend of ``axes`` with no mark: ``study (S5): B decreases
    with height``.

    A trend or an order has no one place in the data to be drawn at; as a legend entry it stands beside the data
    (the legend is outside them, :func:`legend_outside`) without covering any.

    Parameters
    ----------
    axes : matplotlib.axes.Axes
        The axes whose legend gets the entry.
    note : StudyNote
        The finding.

    Returns
    -------
    matplotlib.lines.Line2D
        The entry's handle: a line with no data and no mark (it moves no axis limit), ``gid="finding <id>"``.
    """
    handle = Line2D([], [], linestyle="none", marker="none", label=note.label, gid=f"finding {note.id}")
    axes.add_line(handle)
    return handle
