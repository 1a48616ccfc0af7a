"""The one Jinja environment that renders engine input decks.

Decks are engine syntax in ``templates/``; every number and name comes from a rendering context that is
checked before rendering. LIGGGHTS executes whatever a line says (``shell``, ``include``, ``variable ...
getenv``), expands ``$x`` even inside quotes, treats ``#`` as a comment and ``&`` as a line join, so a
rendered value may only be a finite number, an identifier-like name, or a relative path made by siloflow. YADE
scripts are Python: the same values, names and paths as quoted string literals (``pystr``), so no value from a
configuration is ever evaluated as code.
"""

from __future__ import annotations

import math
import numbers
import re
from functools import lru_cache
from pathlib import Path
from typing import Any

import jinja2

TEMPLATE_ROOT = Path(__file__).resolve().parent.parent / "templates"
# Applied with fullmatch, to the whole string: a pattern ending in ``$`` also matches before a final newline, and a
# name "twin\n" would end its deck line and start another.
_NAME = re.compile(r"[A-Za-z0-9_.-]+")
_PATH = re.compile(r"[A-Za-z0-9_.-]+(/[A-Za-z0-9_.*-]+)*")


class UnsafeDeckValue(ValueError):
    """A value would not render as a single, inert token in an engine deck."""


def _defined(value: Any) -> Any:
    # Filters receive StrictUndefined objects without touching them; make them fail loudly here.
    if isinstance(value, jinja2.Undefined):
        value._fail_with_undefined_error()
    return value


def deck_number(value: Any) -> str:
    """Render a finite real number so that the engine reads back the same value (``repr`` of a float)."""
    value = _defined(value)
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise UnsafeDeckValue(f"expected a number, got {value!r}")
    if isinstance(value, numbers.Integral):
        return str(int(value))
    as_float = float(value)
    if not math.isfinite(as_float):
        raise UnsafeDeckValue(f"expected a finite number, got {value!r}")
    return repr(as_float)


def deck_integer(value: Any) -> str:
    """Render an integer (step counts, seeds, types)."""
    value = _defined(value)
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise UnsafeDeckValue(f"expected an integer, got {value!r}")
    return str(int(value))


def deck_name(value: Any) -> str:
    """Render a name: letters, digits, ``_ . -`` only."""
    value = _defined(value)
    if not isinstance(value, str) or not _NAME.fullmatch(value):
        raise UnsafeDeckValue(f"expected a name of letters, digits, '_', '.', '-', got {value!r}")
    return value


def deck_path(value: Any) -> str:
    """Render a relative path made by the orchestrator (no '..', no absolute paths, no spaces)."""
    value = _defined(value)
    text = str(value)
    if not _PATH.fullmatch(text) or ".." in text.split("/"):
        raise UnsafeDeckValue(f"expected a relative path of safe characters, got {value!r}")
    return text


def deck_string(value: Any) -> str:
    """Render a name or relative path as a Python string literal (YADE scripts): the checks of :func:`deck_path`,
    then quotes; the characters it allows need no escaping."""
    return repr(deck_path(value))


def check_context(node: Any, where: str = "context") -> None:
    """Walk a rendering context and refuse anything that is not a number, a boolean or a safe string.

    Raises
    ------
    UnsafeDeckValue
        Naming the location of the offending value.
    """
    if isinstance(node, dict):
        for key, value in node.items():
            check_context(value, f"{where}.{key}")
    elif isinstance(node, (list, tuple)):
        for index, value in enumerate(node):
            check_context(value, f"{where}[{index}]")
    elif isinstance(node, bool) or node is None:
        return
    elif isinstance(node, numbers.Real):
        if not math.isfinite(float(node)):
            raise UnsafeDeckValue(f"{where}: {node!r} is not a finite number")
    elif isinstance(node, str):
        if not _PATH.fullmatch(node) or ".." in node.split("/"):
            raise UnsafeDeckValue(f"{where}: {node!r} is not a safe name or relative path")
    else:
        raise UnsafeDeckValue(f"{where}: values of type {type(node).__name__} cannot be rendered into a deck")


@lru_cache(maxsize=None)
def deck_environment(root: Path = TEMPLATE_ROOT) -> jinja2.Environment:
    """The Jinja environment for all engine decks (strict undefined, filters registered by name)."""
    environment = jinja2.Environment(
        loader=jinja2.FileSystemLoader(str(root)),
        undefined=jinja2.StrictUndefined,
        trim_blocks=True,
        lstrip_blocks=True,
        keep_trailing_newline=True,
        autoescape=False,
    )
    environment.filters["num"] = deck_number
    environment.filters["int"] = deck_integer
    environment.filters["name"] = deck_name
    environment.filters["path"] = deck_path
    environment.filters["pystr"] = deck_string
    return environment


def render_deck(template_name: str, context: dict) -> str:
    """Render ``templates/<template_name>`` after checking every value of ``context``."""
    check_context(context)
    return deck_environment().get_template(template_name).render(**context)
