"""How one cell of the summary page prints: numbers to significant digits, "value ± error", yes/no flags.

Pure text formatting, no page structure (that is :mod:`siloflow.analysis.report.summary`). Numbers go through
:class:`decimal.Decimal` from their ``repr``, so that a value rounds as a person reads it (2.675 to 2.68), which
binary floats and ``format`` do not.
"""

from __future__ import annotations

import html
import math
import numbers
from decimal import ROUND_HALF_UP, Decimal

import numpy as np

__all__ = [
    "TEXT",
    "COUNT",
    "NUMBER",
    "ESTIMATE",
    "FLAG",
    "NO_UNCERTAINTY",
    "is_missing",
    "format_number",
    "format_value_with_error",
    "format_cell",
]

#: Column kinds: free text, a whole count, a number shown as it is, a figure of merit that should carry its
#: standard error, a yes/no flag.
TEXT, COUNT, NUMBER, ESTIMATE, FLAG = "text", "count", "number", "estimate", "flag"
#: What a figure of merit without an uncertainty shows after its value.
NO_UNCERTAINTY = "±?"
#: Significant digits of a number printed without an uncertainty.
SIGNIFICANT_DIGITS = 4
#: Decimal exponents outside [-3, 5] print as mantissa × 10^n (a column of zeros or digits is unreadable).
_PLAIN_EXPONENTS = range(-3, 6)
_SUPERSCRIPT = str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹")


def is_missing(value) -> bool:
    return value is None or (isinstance(value, numbers.Real) and not math.isfinite(float(value)))


def _decimal(value: float) -> Decimal:
    # Through repr: the digits a person sees, so 2.675 rounds up as written, not as its binary neighbour.
    return Decimal(repr(float(value)))


def _rounded(value: Decimal, decimals: int) -> Decimal:
    result = value.quantize(Decimal(1).scaleb(-decimals), rounding=ROUND_HALF_UP)
    return result if result != 0 else abs(result)  # no "-0.00"


def _plain(value: Decimal) -> str:
    return format(value, "f")


def _times_ten_to(exponent: int) -> str:
    return f"× 10{str(exponent).translate(_SUPERSCRIPT)}"


def format_number(value) -> str:
    """A number with :data:`SIGNIFICANT_DIGITS` significant digits (whole digits are never cut).

    Magnitudes below 10⁻³ or from 10⁶ print as ``1.235 × 10⁻⁷``; NaN, infinities and None as "n/a".

    Examples
    --------
    >>> format_number(0.123456), format_number(535.9231), format_number(123456.7), format_number(1.2345e-7)
    ('0.1235', '535.9', '123457', '1.235 × 10⁻⁷')
    """
    if is_missing(value):
        return "n/a"
    number = _decimal(value)
    if number == 0:
        return "0"
    exponent = number.adjusted()
    if exponent not in _PLAIN_EXPONENTS:
        return f"{format_number(float(number.scaleb(-exponent)))} {_times_ten_to(exponent)}"
    rounded = _rounded(number, max(0, SIGNIFICANT_DIGITS - 1 - exponent))
    if rounded.adjusted() > exponent:  # 9.9996 rounds to 10.000: one digit too many
        rounded = _rounded(number, max(0, SIGNIFICANT_DIGITS - 2 - exponent))
    return _plain(rounded)


def _with_error(value: Decimal, error: Decimal) -> str:
    """``value ± error``, both finite, error > 0, in plain decimal notation."""
    exponent = error.adjusted()
    decimals = 1 - exponent
    rounded_error = _rounded(error, decimals)
    if rounded_error.adjusted() > exponent:  # 0.0999 rounds to 0.100: keep 2 significant digits, 0.10
        decimals -= 1
        rounded_error = _rounded(error, decimals)
    return f"{_plain(_rounded(value, decimals))} ± {_plain(rounded_error)}"


def format_value_with_error(value, error) -> str:
    """A value with its standard error: the error to 2 significant digits, the value to the same decimal place.

    Parameters
    ----------
    value : float or None
        The value (any unit); None or non-finite prints "n/a".
    error : float or None
        Its standard error (same unit, >= 0). None, NaN or infinite (not estimated) prints the value alone
        (:func:`format_number`) followed by :data:`NO_UNCERTAINTY`; 0 prints "value ± 0".

    Returns
    -------
    str
        E.g. ``"0.1168 ± 0.0021"``; magnitudes below 10⁻³ or from 10⁶ as ``"(1.230 ± 0.045) × 10⁻⁷"``.

    Raises
    ------
    ValueError
        If the error is negative.

    Examples
    --------
    >>> format_value_with_error(0.116844, 0.002134), format_value_with_error(535.92, 12.4)
    ('0.1168 ± 0.0021', '536 ± 12')
    """
    if is_missing(value):
        return "n/a"
    if error is not None and float(error) < 0.0:
        raise ValueError(f"a standard error must be >= 0, got {error!r}")
    if is_missing(error):
        return f"{format_number(value)} {NO_UNCERTAINTY}"
    if float(error) == 0.0:
        return f"{format_number(value)} ± 0"
    number, uncertainty = _decimal(value), _decimal(error)
    exponent = max(number.adjusted() if number != 0 else uncertainty.adjusted(), uncertainty.adjusted())
    if exponent not in _PLAIN_EXPONENTS:
        scaled = _with_error(number.scaleb(-exponent), uncertainty.scaleb(-exponent))
        return f"({scaled}) {_times_ten_to(exponent)}"
    return _with_error(number, uncertainty)


def _is_scalar(value) -> bool:
    return value is None or isinstance(value, (str, bool, np.bool_, numbers.Real))


def _flag(value) -> str:
    if is_missing(value):
        return "n/a"
    # A flag read back from a CSV table is the text "True"/"False" (or 1.0/0.0).
    text = str(value).strip().lower()
    if text in ("true", "yes", "1", "1.0"):
        return "yes"
    if text in ("false", "no", "0", "0.0"):
        return "no"
    raise ValueError(f"{value!r} is not a flag (yes/no)")


def format_cell(value, kind: str = NUMBER, error=None, has_error: bool = False) -> str:
    """A table cell as escaped HTML text.

    Parameters
    ----------
    value : str, bool, number or None
        The cell value. NaN and None print "n/a", booleans "yes"/"no", numbers by :func:`format_number`.
    kind : str
        The column kind (:data:`TEXT`, :data:`COUNT`, :data:`NUMBER`, :data:`ESTIMATE`, :data:`FLAG`).
    error : float or None
        The value's standard error (same unit).
    has_error : bool
        Whether the column carries errors (then a number prints with :func:`format_value_with_error`, as it
        does for the kind :data:`ESTIMATE`).

    Raises
    ------
    TypeError
        If the value is not a scalar (a mapping or a list must be formatted as text by its row builder).
    """
    if not _is_scalar(value):
        raise TypeError(f"a {type(value).__name__} is not a table cell value: format it as text first, got "
                        f"{value!r:.80}")
    if kind == FLAG or isinstance(value, (bool, np.bool_)):
        return _flag(value)
    if isinstance(value, str):
        return html.escape(value)
    if is_missing(value):
        return "n/a"
    if kind == TEXT:
        return html.escape(f"{value:g}")
    if kind == ESTIMATE or has_error or error is not None:
        return html.escape(format_value_with_error(value, error))
    if isinstance(value, numbers.Integral) or (kind == COUNT and float(value).is_integer()):
        return str(int(value))
    return html.escape(format_number(value))
