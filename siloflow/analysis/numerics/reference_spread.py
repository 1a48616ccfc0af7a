"""The spread between seeds when only the reference configuration of a comparison runs with several seeds and the
others with one (``reference_replicates``, :func:`siloflow.model.cases.cases_of`).

A run's figures come as a nested summary (its JSON files, its CSV tables as lists of rows): every number ``x`` whose
standard error sits at the same place under the name ``x_error`` (``{"flow": 0.1, "flow_error": 0.002}``,
``{"index": {"0.04": 0.8}, "index_error": {"0.04": 0.05}}``, ``{"vrr": [3.1, 9.0], "vrr_error": [0.2, 1.1]}``) is a
*figure*. :func:`combine_seeds` turns the reference's seeds into one summary: each figure's mean and the error of
:func:`siloflow.analysis.numerics.replicates.replicate_error` (the larger of the seeds' standard error and the within-run
errors). :func:`relative_spread` is each figure's standard deviation over the seeds relative to its mean, and
:func:`floor_errors` applies it to a configuration run once: its figure's error becomes the larger of its within-run
error and that relative spread times its value, which is what another seed would move it by. Relative, because the
configurations of a comparison differ in level (flow rates, velocities, residence times) more than in the scatter
of a seed relative to it. The validation rows, the blender's comparison of inserts and the recirculating silos'
summary then judge the combined and floored figures as they judge one run's.

Pure: summaries in, summaries out. Strings that read as numbers (CSV rows as read) count as numbers.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Mapping, Sequence

from siloflow.analysis.numerics.replicates import ERROR_SUFFIX, SEED_STD_SUFFIX, replicate_error

__all__ = ["SeedSpread", "combine_seeds", "relative_spread", "table_spread", "floor_table", "floor_errors",
           "with_reference_spread", "seed_note"]

Path = tuple


class SeedSpread(dict):
    """``{figure path: relative standard deviation over the seeds}`` with the number of seeds (``seeds``)."""

    def __init__(self, spread: Mapping, seeds: int):
        super().__init__(spread)
        self.seeds = seeds


def _number(value) -> float | None:
    """``value`` as a float when it is a number or a string that reads as one; None otherwise (flags too)."""
    if isinstance(value, bool):
        return None
    if isinstance(value, numbers.Real):
        return float(value)
    if isinstance(value, str):
        try:
            return float(value)
        except ValueError:
            return None
    return None


def _flatten(tree, path: Path = ()) -> dict[Path, object]:
    """``{path: leaf}``: mappings and lists of numbers or mappings are walked; other lists are leaves."""
    if isinstance(tree, Mapping):
        return {key: value for name, child in tree.items() for key, value in _flatten(child, (*path, name)).items()}
    if isinstance(tree, (list, tuple)) and all(isinstance(v, Mapping) or _number(v) is not None for v in tree) and tree:
        return {key: value for index, child in enumerate(tree) for key, value in _flatten(child, (*path, index)).items()}
    return {path: tree}


def _error_path(path: Path, leaves: Mapping[Path, object]) -> Path | None:
    """Where the standard error of the leaf at ``path`` is: the first of its names, from the last, that with
    ``_error`` appended is a leaf; None when none is."""
    for position in range(len(path) - 1, -1, -1):
        name = path[position]
        if isinstance(name, str) and not name.endswith(ERROR_SUFFIX):
            candidate = (*path[:position], name + ERROR_SUFFIX, *path[position + 1:])
            if candidate in leaves:
                return candidate
    return None


def _figures(leaves: Mapping[Path, object]) -> dict[Path, Path]:
    """``{figure path: its error's path}`` of the numeric leaves that have an error."""
    found = {}
    for path, value in leaves.items():
        if _number(value) is None:
            continue
        error = _error_path(path, leaves)
        if error is not None and error != path:
            found[path] = error
    return found


def _set(tree, path: Path, value):
    """A copy of ``tree`` with the leaf at ``path`` replaced (the containers along the path copied)."""
    if not path:
        return value
    head, rest = path[0], path[1:]
    if isinstance(tree, Mapping):
        copy = dict(tree)
    else:
        copy = list(tree)
    copy[head] = _set(tree[head], rest, value)
    return copy


def _merged_leaf(values: Sequence):
    """A leaf that is not a figure, over the seeds: flags true when any is (item by item in lists of flags, a VRR at
    its ceiling in one seed is at it), numbers their mean when they differ, other lists the union of their items,
    anything else the first seed's."""
    first = values[0]
    if all(isinstance(v, bool) for v in values):
        return any(values)
    numbers_ = [_number(v) for v in values]
    if all(n is not None for n in numbers_) and len(set(numbers_)) > 1:
        return math.fsum(numbers_) / len(numbers_)
    if all(isinstance(v, (list, tuple)) for v in values):
        flags = [v for v in values if v and all(isinstance(item, bool) for item in v)]
        if len(flags) == len(values) and len({len(v) for v in values}) == 1:
            return [any(items) for items in zip(*values)]
        return list(dict.fromkeys(item for v in values for item in v))
    return first


def combine_seeds(summaries: Sequence) -> tuple[object, SeedSpread]:
    """One summary from the same configuration's runs with different seeds, and the figures' relative spread.

    Parameters
    ----------
    summaries : sequence
        The runs' summaries (nested mappings and lists, see the module docstring), at least one; a leaf missing from
        one of them (a table with fewer rows) is taken from the first.

    Returns
    -------
    combined : same type as the first summary
        The first summary with every figure replaced by its mean over the seeds and its error by the error of
        :func:`siloflow.analysis.numerics.replicates.replicate_error`; every other leaf merged (see :func:`_merged_leaf`).
    spread : SeedSpread
        :func:`relative_spread` of the seeds.

    Raises
    ------
    ValueError
        Without summaries.
    """
    if not summaries:
        raise ValueError("combine_seeds needs at least one summary")
    flats = [_flatten(summary) for summary in summaries]
    combined = summaries[0]
    figures = _figures(flats[0])
    errors = set(figures.values())
    for path in flats[0]:
        if path in errors or path in figures:
            continue
        present = [flat[path] for flat in flats if path in flat]
        combined = _set(combined, path, _merged_leaf(present))
    for path, error_path in figures.items():
        pairs = [(_number(flat.get(path)), _number(flat.get(error_path))) for flat in flats]
        pairs = [(v, math.nan if e is None else e) for v, e in pairs if v is not None and math.isfinite(v)]
        if not pairs:
            continue
        mean, error, _ = replicate_error([v for v, _ in pairs], [max(e, 0.0) if math.isfinite(e) else math.nan
                                                                 for _, e in pairs])
        combined = _set(_set(combined, path, mean), error_path, error)
    return combined, relative_spread(summaries)


def relative_spread(summaries: Sequence) -> SeedSpread:
    """Each figure's sample standard deviation over the seeds over the absolute mean (-): ``{path: spread}`` of the
    figures finite in at least two seeds with a non-zero mean, and the number of seeds."""
    flats = [_flatten(summary) for summary in summaries]
    spread = {}
    for path in _figures(flats[0]) if flats else {}:
        values = [_number(flat.get(path)) for flat in flats]
        values = [v for v in values if v is not None and math.isfinite(v)]
        if len(values) < 2:
            continue
        mean = math.fsum(values) / len(values)
        if mean == 0.0:
            continue
        std = math.sqrt(math.fsum((v - mean) ** 2 for v in values) / (len(values) - 1))
        spread[path] = std / abs(mean)
    return SeedSpread(spread, len(summaries))


def table_spread(rows: Sequence[Mapping], figures: Sequence[str] | None = None) -> tuple[SeedSpread, list[Mapping]]:
    """The relative spread between seeds of a table whose replicated rows are already combined
    (:func:`siloflow.analysis.numerics.replicates.combine_replicates`: ``replicates``, ``<figure>_seed_std``).

    Parameters
    ----------
    rows : sequence of mapping
        The table's rows (strings that read as numbers count as numbers).
    figures : sequence of str, optional
        The columns whose spread to take; default: every column with a ``<figure>_seed_std`` in a replicated row.

    Returns
    -------
    spread : SeedSpread
        ``{(figure,): seed std / |value|}``, the largest over the replicated rows, with their largest seed count
        (1 and no figure when no row is replicated).
    replicated : list of mapping
        The replicated rows.
    """
    replicated = [row for row in rows if (_number(row.get("replicates")) or 1) >= 2]
    if figures is None:
        figures = list(dict.fromkeys(column[: -len(SEED_STD_SUFFIX)] for row in replicated for column in row
                                     if column.endswith(SEED_STD_SUFFIX)))
    spread = {}
    for figure in figures:
        ratios = []
        for row in replicated:
            value, std = _number(row.get(figure)), _number(row.get(figure + SEED_STD_SUFFIX))
            if value and std is not None and math.isfinite(std) and math.isfinite(value):
                ratios.append(std / abs(value))
        if ratios:
            spread[(figure,)] = max(ratios)
    seeds = max((int(_number(row["replicates"])) for row in replicated), default=1)
    return SeedSpread(spread, seeds), replicated


def floor_table(rows: Sequence[Mapping], figures: Sequence[str] | None = None) -> tuple[list, SeedSpread, list]:
    """A combined table's rows with the rows run once floored by the replicated rows' spread (:func:`table_spread`,
    :func:`floor_errors`): ``(rows, spread, replicated rows)``, the rows in their order."""
    spread, replicated = table_spread(rows, figures)
    return [row if row in replicated else floor_errors(row, spread) for row in rows], spread, replicated


def floor_errors(summary, spread: Mapping[Path, float]):
    """``summary`` of a configuration run once, with each figure's error raised to its relative seed spread times
    its absolute value where that is larger (an unknown within-run error becomes the spread's). Figures without a
    spread keep their error."""
    flat = _flatten(summary)
    floored = summary
    for path, error_path in _figures(flat).items():
        if path not in spread:
            continue
        value = _number(flat[path])
        error = _number(flat[error_path])
        floor = spread[path] * abs(value)
        if math.isfinite(floor) and not (error is not None and math.isfinite(error) and error >= floor):
            floored = _set(floored, error_path, floor)
    return floored


def with_reference_spread(summaries: Sequence, run_ids: Sequence[str], reference: set[str]):
    """The reference configuration's seeds combined and every other run's errors floored by their spread.

    Parameters
    ----------
    summaries : sequence
        The runs' summaries, in the order of ``run_ids``.
    run_ids : sequence of str
        Their run ids.
    reference : set of str
        The run ids of the reference configuration's seeds (at least one of ``run_ids``).

    Returns
    -------
    combined : object
        The reference's summary over its seeds (:func:`combine_seeds`).
    others : list of (str, object)
        ``(run id, summary)`` of every other run, errors floored (:func:`floor_errors`), in order.
    spread : SeedSpread
    """
    combined, spread = combine_seeds([summary for run, summary in zip(run_ids, summaries) if run in reference])
    others = [(run, floor_errors(summary, spread)) for run, summary in zip(run_ids, summaries) if run not in reference]
    return combined, others, spread


def seed_note(reference: str, spread: SeedSpread, reference_row: bool) -> str:
    """The evidence a row adds about the seeds, saying exactly how the spread between them enters its error: the
    reference configuration's mean over its seeds, or a configuration run once whose error is floored by the
    reference's spread (:func:`floor_errors`)."""
    if spread.seeds < 2:
        return "one seed: within-run error only"
    dof = f"{spread.seeds - 1} degrees of freedom"
    if reference_row:
        return (f"mean of {spread.seeds} seeds; its error is the larger of the standard error of their mean and the "
                f"within-run errors; {dof}")
    return (f"one seed; its error is the larger of its within-run error and its value times the standard deviation "
            f"between the {spread.seeds} seeds of {reference} relative to their mean; {dof}")
