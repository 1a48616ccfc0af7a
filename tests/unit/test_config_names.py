"""Names are matched whole: a name with a trailing newline is refused at every place the schema or a deck takes one.

Python's ``$`` (which jsonschema's ``pattern`` and ``re.match`` use) also matches before a final newline, so a
particle model named "twin\\n" once passed and split a LIGGGHTS ``fix`` line. The places are found by walking the
schema and the deck environment's filters, so that a new pattern or filter is covered without touching this file.
"""

from __future__ import annotations

import copy
import re
from typing import NamedTuple

import pytest

from siloflow.engines.config import ConfigError, load_config_file, load_schema, validate_config
from tests.repo import REPO_ROOT
from siloflow.engines.templating import UnsafeDeckValue, check_context, deck_environment

#: A name every pattern of the schema and of the decks accepts, and the same with a trailing newline.
NAME = "twin"
BAD_NAME = NAME + "\n"
#: Stands for "any key" of a mapping in a position (``additionalProperties``).
ENTRY = "<entry>"
#: A walk that finds fewer positions has lost its way (there are about fifty: a dozen sections name materials,
#: particle models, presets, layouts, insert configurations and tests).
FEWEST_POSITIONS = 40


class Position(NamedTuple):
    """A place of the configuration that a ``pattern`` checks.

    Attributes
    ----------
    kind : str
        ``"value"``: the string at ``path``; ``"name"``: the keys of the mapping at ``path`` (``propertyNames``).
    path : tuple
        Keys from the top; a list's items at index 0, any key of a mapping as :data:`ENTRY`.
    pattern : str
        The pattern that checks it.
    entry : dict or None
        For a ``"name"``, the schema of the mapping's values.
    """

    kind: str
    path: tuple
    pattern: str
    entry: dict | None = None


def _resolved(node: dict, definitions: dict) -> dict:
    """``node`` with a ``#/definitions/...`` reference replaced by its definition (the node's own keys kept)."""
    reference = node.get("$ref", "")
    if not reference.startswith("#/definitions/"):
        return node
    own = {key: value for key, value in node.items() if key != "$ref"}
    return {**_resolved(definitions[reference.rsplit("/", 1)[1]], definitions), **own}


def name_positions(schema: dict) -> list[Position]:
    """Every place of the configuration that a ``pattern`` of ``schema`` checks, in the schema's order."""
    definitions = schema.get("definitions", {})
    found = []

    def walk(node, path):
        if not isinstance(node, dict):
            return
        node = _resolved(node, definitions)
        if "pattern" in node:
            found.append(Position("value", path, node["pattern"]))
        names = _resolved(node.get("propertyNames") or {}, definitions)
        if "pattern" in names:
            found.append(Position("name", path, names["pattern"], node.get("additionalProperties") or {}))
        for key, sub in node.get("properties", {}).items():
            walk(sub, path + (key,))
        walk(node.get("additionalProperties"), path + (ENTRY,))
        walk(node.get("items"), path + (0,))
        for key in ("oneOf", "anyOf", "allOf"):
            for sub in node.get(key, []):
                walk(sub, path)

    walk(schema, ())
    return found


def _key(path: tuple) -> str:
    """The key as validation names it: ``contacts[0].materials[0]``."""
    text = ""
    for element in path:
        text += f"[{element}]" if isinstance(element, int) else ("." if text else "") + element
    return text


def _minimal(node: dict, definitions: dict):
    """A small instance of ``node`` the schema accepts (for a mapping whose default has no entry to copy)."""
    node = _resolved(node, definitions)
    if "oneOf" in node or "anyOf" in node:
        return _minimal((node.get("oneOf") or node["anyOf"])[0], definitions)
    if "default" in node:
        return copy.deepcopy(node["default"])
    if node.get("type") == "object" or "properties" in node:
        return {key: _minimal(node["properties"][key], definitions) for key in node.get("required", [])}
    if node.get("type") == "number":
        return 1.0
    raise AssertionError(f"no minimal instance for {node}; extend _minimal")


def with_value(config: dict, path: tuple, value: str) -> tuple[dict, tuple]:
    """A copy of ``config`` with ``value`` at ``path``, and the concrete path (:data:`ENTRY` made a key the
    mapping has, a missing or null list made one)."""
    config = copy.deepcopy(config)
    concrete: list = []
    node = config
    for position, element in enumerate(path):
        if element == ENTRY:
            assert node, f"{_key(tuple(concrete))} has no entry to put a name into"
            element = next(iter(node))
        if isinstance(element, int) and not node:
            node.append(None)
        concrete.append(element)
        if position == len(path) - 1:
            node[element] = value
        elif node[element] is None:
            node[element] = []  # a list that may be null (jenike.sweep.wall_test_shapes)
        node = node[element]
    return config, tuple(concrete)


def with_name(config: dict, position: Position, name: str, definitions: dict) -> dict:
    """A copy of ``config`` with one more entry named ``name`` in the mapping at ``position``: a copy of one it
    has, else a minimal one."""
    config = copy.deepcopy(config)
    mapping = config
    for element in position.path:
        mapping = mapping[element]
    value = next(iter(mapping.values())) if mapping else _minimal(position.entry, definitions)
    mapping[name] = copy.deepcopy(value)
    return config


SCHEMA = load_schema()
POSITIONS = name_positions(SCHEMA)


@pytest.fixture(scope="module")
def filled():
    """The default configuration with every default filled, which validates again as it is: every key is there."""
    return validate_config(load_config_file(REPO_ROOT / "config" / "config.yaml"))


def test_the_walk_finds_every_kind_of_name_position():
    assert len(POSITIONS) >= FEWEST_POSITIONS, [_key(position.path) for position in POSITIONS]
    found = {(position.kind, _key(position.path)) for position in POSITIONS}
    # each way a name is given: a value, an item of a list, a key of a mapping, a key of a list's objects, a path
    assert {("value", "defaults.particle_model"), ("value", "jenike.sweep.shapes[0]"), ("name", "particle_models"),
            ("value", "silo_recirculation.layouts[0].name"), ("name", "silo_flat.existing_runs"),
            ("value", "engine.liggghts.executable")} <= found


@pytest.mark.parametrize("position", POSITIONS, ids=lambda position: f"{position.kind}:{_key(position.path)}")
def test_a_name_with_a_trailing_newline_is_refused_naming_the_key(position, filled, tmp_path, monkeypatch):
    # jsonschema applies a pattern with re.search: the name alone passes, with the newline it does not
    assert re.search(position.pattern, NAME) and not re.search(position.pattern, BAD_NAME), position.pattern
    monkeypatch.chdir(tmp_path)
    if position.kind == "name":  # the key named is the mapping's
        config, key = with_name(filled, position, BAD_NAME, SCHEMA["definitions"]), position.path
    else:
        config, key = with_value(filled, position.path, BAD_NAME)
    with pytest.raises(ConfigError) as caught:
        validate_config(config)
    message = str(caught.value)
    assert message.startswith(f"config key '{_key(key)}': {BAD_NAME!r} does not match"), message
    assert "\n" not in message  # one line
    assert list(tmp_path.iterdir()) == []  # refused before anything is written


def test_every_deck_filter_and_the_context_check_refuse_a_name_with_a_trailing_newline():
    ours = {name: function for name, function in deck_environment().filters.items()
            if getattr(function, "__module__", "") == "siloflow.engines.templating"}
    # names, paths and YADE's string literals take strings; numbers and integers refuse them anyway
    assert {"name", "path", "pystr", "num", "int"} <= set(ours)
    for function in ours.values():
        with pytest.raises(UnsafeDeckValue):
            function(BAD_NAME)
    for name in ("name", "path", "pystr"):
        assert NAME in ours[name](NAME)  # the name without the newline renders
    with pytest.raises(UnsafeDeckValue, match=r"context\.particle\.name: 'twin\\n' is not a safe name"):
        check_context({"particle": {"name": BAD_NAME}})
    check_context({"particle": {"name": NAME}})
