"""The configuration reference: one Markdown page listing every key of the configuration schema.

The schema (``siloflow/workflow/schemas/config.schema.yaml`` and its case kinds' fragments, assembled by
:func:`siloflow.engines.config.load_schema`) is where each key's description and default are written;
:func:`render_reference` turns it into ``docs/configuration-reference.md``, one table per top-level section with
each key's dotted path, type, unit, default and description, so that the manual carries the keys without a second
copy of them to keep up to date (tests/unit/test_config_reference.py checks that the committed page is what the
schema gives). :func:`keys_lacking_description_or_default` lists the keys that break the project's rule that every
key has a description and a default.

Regenerate the page after changing the schema::

    .venv/bin/python -m siloflow.engines.config_reference docs/configuration-reference.md
"""

from __future__ import annotations

import argparse
import re
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Iterator, Mapping, Sequence

import yaml

from siloflow.engines.config import load_schema

__all__ = ["SchemaKey", "keys_lacking_description_or_default", "main", "render_reference", "schema_keys",
           "unit_of"]

#: How the key of a map entry and an item of a list appear in a dotted path (`materials.<name>.density`,
#: `contacts[].restitution`); tests/unit/test_docs.py reads both forms.
MAP_KEY = "<name>"
LIST_ITEM = "[]"
#: Defaults longer than this (characters, on one line) are written as YAML blocks below their section's table.
LONG_DEFAULT = 80
#: The command that writes the page, quoted in its header.
REGENERATE = "python -m siloflow.engines.config_reference docs/configuration-reference.md"

# The schema states a key's unit in its description, in parentheses after the quantity: "Downward velocity of
# inserted clumps (m/s)", "(kg/m^3)", "(-)" for a dimensionless one, sometimes after a remark ("(coefficients, -)",
# "(px, rows down)", "(s after the outlet opened)"). A parenthesised part is read as the unit when it is made of
# these units only (or is one followed by the event a time counts from), so that "(x, z)", "(1, a 3 x 3 window)" or
# "(the study's 270 mm)" are not.
_BASE_UNITS = r"(?:m|mm|s|kg|Pa|kPa|J|N|W|K|Hz|px|rad|degrees)"
_UNIT = re.compile(rf"(?P<unit>-|(?:1(?=\s*/)|{_BASE_UNITS}(?:\^?-?\d)?)(?:\s*/\s*{_BASE_UNITS}(?:\^?-?\d)?)*)"
                   r"(?:\s+(?:after|before|since)\s.*)?")
_PARENTHESISED = re.compile(r"\(([^()]*)\)")
_NUMERIC_TYPES = {"number", "integer"}


@dataclass(frozen=True)
class SchemaKey:
    """One key of the configuration, as the reference lists it.

    Attributes
    ----------
    path : str
        Dotted path from the top-level section (``silo_flat.fill.insertion_velocity``); a map's entries appear as
        ``<name>`` and a list's items as ``[]`` (``materials.<name>.density``, ``contacts[].restitution``).
    schema : dict
        The key's schema with its ``$ref`` resolved: the referenced definition overlaid with the key's own words.
    required : bool
        Whether the object holding the key lists it as required.
    declared : bool
        Whether the key is reached from the top through declared ``properties`` only, not through a map entry or a
        list item: the keys the rule "every key has a description and a default" applies to (an entry of a map or
        an item of a list takes its values from the map's or the list's default).
    """

    path: str
    schema: dict
    required: bool
    declared: bool

    @property
    def section(self) -> str:
        """The top-level section the key belongs to."""
        return re.split(r"[.\[]", self.path, maxsplit=1)[0]


# --- Walking the schema ----------------------------------------------------------------------------------------------

def _follow_pointer(root: Mapping, reference: str) -> dict:
    """The node a local ``$ref`` (``#/definitions/x``, ``#/$defs/x``) points at in ``root``."""
    if not reference.startswith("#/"):
        raise ValueError(f"only local $refs are supported, not {reference!r}")
    node: Any = root
    for part in reference[2:].split("/"):
        node = node[part.replace("~1", "/").replace("~0", "~")]  # JSON pointer escapes
    return node


def _resolved(node: Any, root: Mapping) -> tuple[dict, frozenset[str]]:
    """``node`` with its ``$ref`` chain resolved (the definition, overlaid with the node's own keys, as the
    validator's defaults and tests/unit/test_config.py read it) and the references followed."""
    if not isinstance(node, Mapping):
        return {}, frozenset()
    followed: set[str] = set()
    merged = dict(node)
    while "$ref" in merged and merged["$ref"] not in followed:
        reference = merged.pop("$ref")
        followed.add(reference)
        merged = {**_follow_pointer(root, reference), **merged}
    merged.pop("$ref", None)
    return merged, frozenset(followed)


def _branches(node: Mapping) -> list:
    """The alternatives and parts of a node (``oneOf``, ``anyOf``, ``allOf``)."""
    return [branch for keyword in ("oneOf", "anyOf", "allOf") for branch in node.get(keyword, [])]


def _walk(node: Mapping, path: str, root: Mapping, declared: bool, expanding: frozenset[str]) -> Iterator[SchemaKey]:
    """The keys below ``node`` (resolved), depth first in the schema's order."""
    required = set(node.get("required", []))
    for name, child in node.get("properties", {}).items():
        schema, followed = _resolved(child, root)
        child_path = f"{path}.{name}" if path else name
        yield SchemaKey(child_path, schema, name in required, declared)
        if not followed & expanding:  # a recursive $ref is listed once, not expanded forever
            yield from _walk(schema, child_path, root, declared, expanding | followed)
    for inner, suffix in _containers(node):
        schema, followed = _resolved(inner, root)
        if not followed & expanding:
            yield from _walk(schema, path + suffix, root, False, expanding | followed)
    for branch in _branches(node):
        schema, followed = _resolved(branch, root)
        if not followed & expanding:
            yield from _walk(schema, path, root, declared, expanding | followed)


def _containers(node: Mapping) -> list[tuple[Any, str]]:
    """The schemas of a map's entries and of a list's items, with the path suffix that stands for one of them."""
    found = [(value, f".{MAP_KEY}") for value in node.get("patternProperties", {}).values()]
    if isinstance(node.get("additionalProperties"), Mapping):
        found.append((node["additionalProperties"], f".{MAP_KEY}"))
    if isinstance(node.get("items"), Mapping):
        found.append((node["items"], LIST_ITEM))
    return found


def schema_keys(schema: Mapping) -> list[SchemaKey]:
    """Every key of an assembled configuration schema, depth first in the schema's order.

    Parameters
    ----------
    schema : mapping
        The JSON schema of the whole configuration (``properties`` are its top-level sections; ``$ref`` point into
        it), as :func:`siloflow.engines.config.load_schema` returns it.

    Returns
    -------
    list of SchemaKey
        One per path; where alternatives (``oneOf``, ``anyOf``) declare the same key, the first one's.
    """
    unique: dict[str, SchemaKey] = {}
    for key in _walk(schema, "", schema, True, frozenset()):
        unique.setdefault(key.path, key)
    return list(unique.values())


def keys_lacking_description_or_default(schema: Mapping) -> list[tuple[str, tuple[str, ...]]]:
    """The keys that break the rule "every key has a description and a default".

    The rule is the one tests/unit/test_config.py checks: it applies to the keys reached through declared
    ``properties`` (a ``$ref``'s definition may give either), not to the keys of a map's entries or a list's items,
    which must be given when the entry is (``materials.<name>.youngs_modulus``) or take the map's or list's default.

    Parameters
    ----------
    schema : mapping
        The assembled configuration schema.

    Returns
    -------
    list of (str, tuple of str)
        Each offending key's path and what it lacks (``"description"``, ``"default"``), in the schema's order;
        empty when every key follows the rule.
    """
    lacking = []
    for key in schema_keys(schema):
        missing = tuple(field for field in ("description", "default") if field not in key.schema)
        if key.declared and missing:
            lacking.append((key.path, missing))
    return lacking


# --- What the reference says of a key --------------------------------------------------------------------------------

def _plain_types(node: Mapping, root: Mapping) -> set[str]:
    """The JSON types a value of ``node`` may have, alternatives included (an enum's from its values)."""
    declared = node.get("type", [])
    types = set([declared] if isinstance(declared, str) else declared)
    if "enum" in node:
        types |= {"null" if value is None else "boolean" if isinstance(value, bool) else
                  "integer" if isinstance(value, int) else "number" if isinstance(value, float) else "string"
                  for value in node["enum"]}
    for branch in _branches(node):
        types |= _plain_types(_resolved(branch, root)[0], root)
    return types


def _is_numeric(node: Mapping, root: Mapping) -> bool:
    """Whether a value of ``node`` is a quantity: numbers, or a list or map of them (a unit applies)."""
    types = _plain_types(node, root) - {"null"}
    if types and types <= _NUMERIC_TYPES:
        return True
    if node.get("properties"):
        return False  # a group of keys, whose own keys carry the units
    alternatives = [node, *(_resolved(branch, root)[0] for branch in _branches(node))]
    inner = [_resolved(entry, root)[0] for each in alternatives for entry, _ in _containers(each)]
    return bool(inner) and all(_is_numeric(each, root) for each in inner)


def unit_of(description: str) -> str:
    """The unit a description states: the first parenthesised part made of units only (or whose first or last
    comma-separated part is), ``-`` for a dimensionless quantity; empty when there is none.

    Examples
    --------
    >>> unit_of("Downward velocity of inserted clumps (m/s). At most 100 m/s.")
    'm/s'
    >>> unit_of("A parameter's prior (coefficients, -).")
    '-'
    >>> unit_of("Runs per engine (seeds silo_flat.seed, +1, ...).")
    ''
    """
    for group in _PARENTHESISED.findall(description):
        parts = [part.strip() for part in re.split(r"[,;]", group)]
        for part in (parts[0], parts[-1]):
            if (match := _UNIT.fullmatch(part)):
                return re.sub(r"(?<=[a-z])(\d)", r"^\1", match["unit"])  # kg/m3 written kg/m^3, as elsewhere
    return ""


def _yaml_value(value: Any) -> str:
    """A value as it is written in a config file (YAML flow style, on one line)."""
    text = yaml.safe_dump(value, default_flow_style=True, sort_keys=False, width=1 << 30, allow_unicode=True)
    return text.strip().removesuffix("...").strip()


def _describe_type(node: Mapping, root: Mapping) -> str:
    """A key's type in words: ``number or null``, ``array of object``, ``map of name to number``, enums with their
    allowed values."""
    declared = node.get("type", [])
    words = [declared] if isinstance(declared, str) else list(declared)
    if "enum" in node:
        allowed = ", ".join(f"`{_yaml_value(value)}`" for value in node["enum"])
        words = [f"{' or '.join(words)}, one of: {allowed}" if words else f"one of: {allowed}"]
    elif "array" in words and isinstance(node.get("items"), Mapping):
        item = _describe_type(_resolved(node["items"], root)[0], root)
        words[words.index("array")] = f"array of ({item})" if "," in item or " or " in item else f"array of {item}"
    if "object" in words and not node.get("properties"):
        entries = [_resolved(inner, root)[0] for inner, suffix in _containers(node) if suffix != LIST_ITEM]
        if entries:
            names = (node.get("propertyNames") or {}).get("enum")
            named = f"name (one of: {', '.join(f'`{name}`' for name in names)})" if names else "name"
            words[words.index("object")] = f"map of {named} to {' or '.join(_describe_type(e, root) for e in entries)}"
    for branch in _branches(node):
        words.append(_describe_type(_resolved(branch, root)[0], root))
    unique = list(dict.fromkeys(word for word in words if word))
    return " or ".join(unique) if unique else "any"


# --- The page --------------------------------------------------------------------------------------------------------

_CODE_SPAN = re.compile(r"(`+)(.+?)\1", re.S)


def _cell(text: str) -> str:
    """Prose for a table cell: on one line, with what Markdown would take for markup escaped outside code spans
    (a `|` ends the cell, `<name>` is an HTML tag, `*` starts emphasis)."""
    text = " ".join(text.split())
    pieces, last = [], 0
    for match in _CODE_SPAN.finditer(text):
        pieces += [_escape(text[last:match.start()]), match.group(0)]
        last = match.end()
    return "".join([*pieces, _escape(text[last:])])


def _escape(prose: str) -> str:
    return prose.replace("\\", "\\\\").replace("|", "\\|").replace("*", "\\*").replace("<", "&lt;")


def _row(key: SchemaKey, root: Mapping) -> str:
    description = key.schema.get("description", "")
    unit = unit_of(description) if _is_numeric(key.schema, root) else ""
    cells = [f"`{key.path}`", _cell(_describe_type(key.schema, root)), unit, _default(key), _cell(description)]
    return "| " + " | ".join(cells) + " |"


def _default(key: SchemaKey) -> str:
    if "default" not in key.schema:
        return "required" if key.required else ""
    value = _yaml_value(key.schema["default"])
    return "below the table" if len(value) > LONG_DEFAULT else f"`{value}`"


def _default_block(key: SchemaKey) -> list[str]:
    """A long default as the config file would write it (a YAML block under the key's path), or nothing for a
    short one."""
    if "default" not in key.schema or len(_yaml_value(key.schema["default"])) <= LONG_DEFAULT:
        return []
    parts = key.path.split(".") if not re.search(r"<|\[", key.path) else [key.path.rsplit(".", 1)[-1]]
    nested: Any = key.schema["default"]
    for part in reversed(parts):
        nested = {part: nested}
    text = yaml.safe_dump(nested, default_flow_style=None, sort_keys=False, width=1 << 30,
                          allow_unicode=True)
    return [f"Default of `{key.path}`:", "", "```yaml", *text.rstrip("\n").splitlines(), "```", ""]


_INTRODUCTION = """\
<!-- Generated from the configuration schema by `{command}`: edit the schema, not this page. -->
# Configuration reference

Every key of a siloflow configuration, generated from the schema
(`siloflow/workflow/schemas/config.schema.yaml` and the case sections' fragments in `siloflow/workflow/schemas/cases/`);
[Configuration](configuration.md) says how a config file is used, validated and inherited.

{description}

How to read the tables:

- **Key**: the dotted path of the key. `<name>` stands for a name you choose (an entry of a map, such as a material
  in `materials.<name>.density`); `[]` for each item of a list (`contacts[].restitution`).
- **Type**: the values the key takes; `one of:` lists the allowed values.
- **Unit**: the unit the value is in, `-` for a dimensionless one; blank where the value has none (a name, a switch,
  a count, a group of keys).
- **Default**: the value a key takes when the config leaves it out. A key of a map's entry or of a list's item has
  none of its own (the map's or the list's default gives it); `required` where the entry must give it.

The silo-type case sections (`silo_flat`, `silo_recirculation`, `blender`) inherit every shared key they leave out
from `defaults`, leaf by leaf: their defaults below apply only where `defaults` does not set the key.

Regenerate this page after changing the schema:

```bash
.venv/bin/{command}
```
"""


def render_reference(schema: Mapping) -> str:
    """The configuration reference page (Markdown) of an assembled configuration schema.

    Parameters
    ----------
    schema : mapping
        The JSON schema of the whole configuration, as :func:`siloflow.engines.config.load_schema` returns it:
        ``properties`` are the top-level sections, in the order the page lists them.

    Returns
    -------
    str
        The page: an introduction, then per top-level section a heading, its description and a table with one row
        per key below the section: ``Key | Type | Unit | Default | Description``.
    """
    description = " ".join(schema.get("description", "").split())
    lines = [_INTRODUCTION.format(command=REGENERATE, description=_cell(description))]
    by_section: dict[str, list[SchemaKey]] = {}
    for key in schema_keys(schema):
        by_section.setdefault(key.section, []).append(key)
    for section, (own, *inner) in by_section.items():
        # the section's own entry heads its table as prose: its description is often a paragraph long
        own_type = f"Type: {_cell(_describe_type(own.schema, schema))}. Default:"
        block = _default_block(own)[1:]  # a long default as a YAML block, a short one on the line
        lines += [f"## {section}", "", _cell(own.schema.get("description", "")), "",
                  *([own_type, *block] if block else [f"{own_type} {_default(own) or 'none'}.", ""])]
        if inner:
            lines += ["| Key | Type | Unit | Default | Description |", "| --- | --- | --- | --- | --- |"]
            lines += [_row(key, schema) for key in inner]
            lines.append("")
            lines += [line for key in inner for line in _default_block(key)]
    return "\n".join(lines)


# --- Writing it ------------------------------------------------------------------------------------------------------

def main(argv: Sequence[str] | None = None) -> int:
    """Write the configuration reference of the installed schema to a file.

    Parameters
    ----------
    argv : sequence of str, optional
        The command line's arguments (default: ``sys.argv[1:]``): the output file.

    Returns
    -------
    int
        0 when the page is written; 2 when the file cannot be written (one line on stderr says why).
    """
    parser = argparse.ArgumentParser(
        prog="python -m siloflow.engines.config_reference",
        description="Write the configuration reference (Markdown) generated from siloflow's configuration schema.")
    parser.add_argument("output", type=Path, help="the Markdown file to write (docs/configuration-reference.md)")
    arguments = parser.parse_args(argv)
    page = render_reference(load_schema())  # reading the schema files is the edge's job, not the renderer's
    try:
        arguments.output.write_text(page, encoding="utf-8")
    except OSError as error:
        print(f"config_reference: cannot write {arguments.output}: {error.strerror or error}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
