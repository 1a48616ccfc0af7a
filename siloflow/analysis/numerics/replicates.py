"""Replicate runs (the same case with different seeds) combined into one figure with its uncertainty.

A configuration with ``replicates: N`` runs every case N times, seed, seed + 1, ..., seed + N - 1
(:func:`siloflow.model.cases.cases_of`). A stage table then has N rows per configuration; :func:`combine_replicates`
turns them into one row per configuration: the mean of each figure and its standard error.

Which error: with N >= 2 the spread over seeds is the honest uncertainty of a figure, since it includes
everything a seed changes (the packing, the flow's own fluctuations), which the within-run error of one run
(batch means, counting noise) cannot see. With 2 or 3 seeds, though, the sample standard deviation is itself
uncertain and can come out small by chance; the combined error is therefore the larger of the seed spread's
standard error ``s / sqrt(N)`` and the within-run errors propagated to the mean, ``sqrt(sum e_i^2) / N``. With
one seed the row passes through with its within-run error.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Mapping, Sequence

import numpy as np

from siloflow.analysis.numerics.uncertainty import combine_independent, seed_spread

__all__ = ["ERROR_SUFFIX", "REPLICATES_KEY", "SEED_STD_SUFFIX", "combine_replicates", "replicate_error"]

#: Suffix of the column that carries a figure's standard error.
ERROR_SUFFIX = "_error"
#: Suffix of the column that carries a figure's sample standard deviation over the seeds.
SEED_STD_SUFFIX = "_seed_std"
#: Column of a combined row: the number of seeds it combines.
REPLICATES_KEY = "replicates"


def replicate_error(values: Sequence[float], errors: Sequence[float]) -> tuple[float, float, float]:
    """Mean, standard error and seed standard deviation of one figure over N replicate runs.

    Parameters
    ----------
    values : sequence of float, length N >= 1
        The figure from each seed, finite, any unit.
    errors : sequence of float, length N
        The within-run standard error of each value (same unit, >= 0, NaN where unknown).

    Returns
    -------
    mean : float
    error : float
        One seed: its within-run error. N >= 2: ``max(s / sqrt(N), sqrt(sum e_i^2) / N)``, or ``s / sqrt(N)``
        when a within-run error is unknown.
    seed_std : float
        The sample standard deviation over the seeds (``ddof=1``); NaN for one seed.

    Raises
    ------
    ValueError
        If the lengths differ, ``values`` is empty or holds a non-finite value, or an error is negative.
    """
    if len(values) != len(errors):
        raise ValueError(f"{len(values)} values but {len(errors)} errors: one error per replicate")
    spread = seed_spread(values)
    propagated = combine_independent(list(errors)) / spread.n
    if spread.n == 1:
        return spread.mean, propagated, math.nan
    if math.isnan(propagated):
        return spread.mean, spread.std_error, spread.std
    return spread.mean, max(spread.std_error, propagated), spread.std


def _is_number(value) -> bool:
    return isinstance(value, numbers.Real) and not isinstance(value, bool)


def _finite_number(value) -> bool:
    return _is_number(value) and math.isfinite(float(value))


def combine_replicates(rows: Sequence[Mapping], keys: Sequence[str]) -> list[dict]:
    """One row per configuration from a table with one row per replicate run.

    Rows with equal values under ``keys`` are replicates of one configuration. In the combined row:

    - every numeric column ``f`` that is not a key and not an error column becomes the mean over the replicates
      where it is finite, ``f_error`` the error of :func:`replicate_error` and, with two or more, ``f_seed_std``
      the seeds' standard deviation (a replicate without a finite ``f`` is left out of ``f``; NaN when none has);
    - a flag (bool) column is true when it is true in any replicate (a VRR at its ceiling in one seed is at it);
    - any other column keeps its value when all replicates agree and is left out otherwise (run ids differ);
    - ``replicates`` counts the rows combined.

    Parameters
    ----------
    rows : sequence of mapping
        The stage table, one row per run; a figure's within-run error is in ``<figure>_error`` (NaN or absent:
        unknown).
    keys : sequence of str
        The columns that name a configuration; every row must have them.

    Returns
    -------
    list of dict
        One row per configuration, in order of first appearance. A configuration run once comes back unchanged
        apart from ``replicates`` = 1.

    Raises
    ------
    KeyError
        If a row lacks a key column (the message names it).
    """
    groups: dict[tuple, list[Mapping]] = {}
    for index, row in enumerate(rows):
        missing = [key for key in keys if key not in row]
        if missing:
            raise KeyError(f"row {index} has no configuration column {missing[0]!r}")
        groups.setdefault(tuple(row[key] for key in keys), []).append(row)
    return [_combine(group, keys) for group in groups.values()]


def _combine(group: Sequence[Mapping], keys: Sequence[str]) -> dict:
    if len(group) == 1:
        return {**group[0], REPLICATES_KEY: 1}
    columns = list(dict.fromkeys(column for row in group for column in row))
    combined: dict = {}
    for column in columns:
        if column in keys:
            combined[column] = group[0][column]
            continue
        if column.endswith(ERROR_SUFFIX) and column[: -len(ERROR_SUFFIX)] in columns:
            continue
        present = [row[column] for row in group if column in row]
        if all(isinstance(value, (bool, np.bool_)) for value in present):
            combined[column] = bool(any(present))
        elif all(_is_number(value) for value in present):
            finite = [row for row in group if _finite_number(row.get(column))]
            if not finite:
                combined[column], combined[column + ERROR_SUFFIX] = math.nan, math.nan
                continue
            errors = [float(row.get(column + ERROR_SUFFIX, math.nan)) for row in finite]
            mean, error, seed_std = replicate_error([float(row[column]) for row in finite], errors)
            combined[column], combined[column + ERROR_SUFFIX] = mean, error
            if len(finite) > 1:
                combined[column + SEED_STD_SUFFIX] = seed_std
        elif len(present) == len(group) and all(value == present[0] for value in present):
            combined[column] = present[0]
    combined[REPLICATES_KEY] = len(group)
    return combined
