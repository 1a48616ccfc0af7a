"""Reading a configuration file as plain data: the one YAML loader of every entry point.

A siloflow configuration is data. PyYAML's safe loader already builds no Python objects, but four things it accepts
would let a file say something other than what its reader sees:

- **YTE.** Snakemake loads config files through YTE, which evaluates ``?``-expressions as Python when the file sets
  ``__use_yte__: true``; Snakemake offers no switch to turn that off. siloflow refuses such a file, so that its own
  commands never hand it to Snakemake.
- **Duplicate keys.** YAML keeps the last of two equal keys without a word (a second ``materials:`` replaces the
  first); here they are refused, naming the key and both lines.
- **YAML 1.1 booleans.** ``yes``, ``no``, ``on`` and ``off`` (any case) are booleans to PyYAML, so a name ``no``
  becomes ``False``; here they are refused, naming the key, with the hint to write ``true``/``false`` for a switch
  or to quote a name.
- **Size.** An alias-expansion bomb (a few lines that expand to gigabytes), deep nesting (a RecursionError) and
  huge files are refused before the schema sees them: at most :data:`MAX_ALIASES` aliases, :data:`MAX_NODES` values
  once every alias is expanded (counted on the composed graph, each shared node once), :data:`MAX_DEPTH` levels and
  :data:`MAX_BYTES` bytes.

The loader is PyYAML's pure-Python safe loader with these checks: a configuration is a few hundred lines, which it
reads in milliseconds (the C loader, used for the schema, cannot be extended this way).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml

__all__ = ["ConfigFileError", "MAX_ALIASES", "MAX_BYTES", "MAX_DEPTH", "MAX_NODES", "YTE_KEY", "load_config_text",
           "read_config_file"]

#: The most aliases (``*name``) a configuration may use: anchors for a few repeated blocks, never a bomb.
MAX_ALIASES = 100
#: The most values (scalars, mappings, sequences) a configuration may expand to with its aliases: the thesis
#: configuration, the largest shipped, holds about 1,000.
MAX_NODES = 100_000
#: The deepest nesting of mappings and sequences: the schema's deepest key is 6 levels down.
MAX_DEPTH = 32
#: The largest configuration file (bytes): the thesis configuration, the largest shipped, is under 20 kB.
MAX_BYTES = 1_000_000
#: The key by which a file asks Snakemake (through YTE) to evaluate its expressions.
YTE_KEY = "__use_yte__"

#: The YAML 1.1 boolean words YAML 1.2 reads as strings: ambiguous in a configuration.
_AMBIGUOUS_BOOLEANS = frozenset({"yes", "no", "on", "off", "y", "n"})


class ConfigFileError(ValueError):
    """A configuration file that is not plain, unambiguous data; the message names the file and the key or line."""


@dataclass(frozen=True)
class _AmbiguousBoolean:
    """A YAML 1.1 boolean word as the loader found it, reported with its key once the file is read."""

    word: str
    line: int


class _StrictLoader(yaml.SafeLoader):
    """PyYAML's safe loader that counts aliases and depth, refuses duplicate keys and keeps YAML 1.1 boolean words
    apart (see the module docstring)."""

    def __init__(self, stream):
        super().__init__(stream)
        self._aliases = 0
        self._depth = 0

    def compose_node(self, parent, index):
        if self.check_event(yaml.AliasEvent):
            self._aliases += 1
            if self._aliases > MAX_ALIASES:
                mark = self.peek_event().start_mark
                raise ConfigFileError(f"line {mark.line + 1}: more than {MAX_ALIASES} aliases (*name); a "
                                      "configuration needs a few at most")
        self._depth += 1
        try:
            if self._depth > MAX_DEPTH:
                mark = self.peek_event().start_mark
                raise ConfigFileError(f"line {mark.line + 1}: nested deeper than {MAX_DEPTH} levels")
            return super().compose_node(parent, index)
        finally:
            self._depth -= 1

    def compose_document(self):
        document = super().compose_document()
        expanded = _expanded_size(document, {})
        if expanded > MAX_NODES:
            raise ConfigFileError(f"its aliases expand it to {expanded:,} values, more than {MAX_NODES:,}")
        return document

    def construct_mapping(self, node, deep=False):
        # merge keys (<<: *name) first, as the safe loader does, so that a merged key is not counted twice
        self.flatten_mapping(node)
        seen: dict[Any, int] = {}
        for key_node, _ in node.value:
            key = self.construct_object(key_node, deep=True)
            line = key_node.start_mark.line + 1
            if isinstance(key, _AmbiguousBoolean):
                raise ConfigFileError(
                    f"line {line}: the key {key.word!r} is a YAML 1.1 boolean; quote it ('{key.word}') to use it as a "
                    "name")
            try:
                first = seen.get(key)
            except TypeError:
                raise ConfigFileError(f"line {line}: a key must be a name or a number, got a "
                                      f"{type(key).__name__}") from None
            if first is not None:
                raise ConfigFileError(f"line {line}: the key {key!r} is given twice (first on line {first}); YAML "
                                      "would silently keep only the last")
            seen[key] = line
        return super().construct_mapping(node, deep=deep)

    def construct_yaml_bool(self, node):
        word = self.construct_scalar(node)
        if word.lower() in _AMBIGUOUS_BOOLEANS:
            return _AmbiguousBoolean(word, node.start_mark.line + 1)
        return super().construct_yaml_bool(node)


_StrictLoader.add_constructor("tag:yaml.org,2002:bool", _StrictLoader.construct_yaml_bool)


def _expanded_size(node: yaml.Node, sizes: dict[int, int]) -> int:
    """The number of values ``node`` stands for with every alias expanded, each shared node sized once (``sizes``:
    by node id), so that a bomb is measured without being expanded. Saturates above :data:`MAX_NODES`."""
    known = sizes.get(id(node))
    if known is not None:
        return known
    size = 1
    if isinstance(node, yaml.MappingNode):
        children = [child for pair in node.value for child in pair]
    elif isinstance(node, yaml.SequenceNode):
        children = node.value
    else:
        children = []
    for child in children:
        size = min(size + _expanded_size(child, sizes), MAX_NODES + 1)
    sizes[id(node)] = size
    return size


def _refuse_ambiguous_booleans(value: Any, path: str, visited: set[int]) -> None:
    """Raise ConfigFileError naming the key of the first YAML 1.1 boolean word under ``value``; a container shared
    through aliases is visited once (``visited``: container ids)."""
    if isinstance(value, _AmbiguousBoolean):
        raise ConfigFileError(
            f"config key '{path}' (line {value.line}): {value.word!r} is a YAML 1.1 boolean; write true or false "
            f"for a switch, or quote it ('{value.word}') for a name")
    if not isinstance(value, (dict, list)) or id(value) in visited:
        return
    visited.add(id(value))
    if isinstance(value, dict):
        for key, item in value.items():
            _refuse_ambiguous_booleans(item, f"{path}.{key}" if path else str(key), visited)
    else:
        for index, item in enumerate(value):
            _refuse_ambiguous_booleans(item, f"{path}[{index}]", visited)


def load_config_text(text: str, source: str = "<config>") -> dict:
    """Parse the text of a configuration file into a dict of plain data.

    Parameters
    ----------
    text : str
        The file's text.
    source : str, optional
        The file's name, for messages.

    Returns
    -------
    dict
        The configuration (empty for an empty file).

    Raises
    ------
    ConfigFileError
        Naming ``source`` and the key or line: YAML that does not parse, a top level that is not a mapping, the YTE
        switch, a duplicate key, a YAML 1.1 boolean word, too many aliases or too deep a nesting.
    """
    if len(text.encode("utf-8")) > MAX_BYTES:
        raise ConfigFileError(f"{source}: larger than {MAX_BYTES:,} bytes; a configuration is a few kilobytes")
    try:
        loaded = yaml.load(text, Loader=_StrictLoader)
    except ConfigFileError as error:
        raise ConfigFileError(f"{source}: {error}") from None
    except yaml.YAMLError as error:
        raise ConfigFileError(f"{source}: not valid YAML: {error}") from None
    if loaded is None:
        return {}
    if not isinstance(loaded, dict):
        raise ConfigFileError(f"{source}: the top level of a config file must be a mapping, got "
                              f"{type(loaded).__name__}")
    if YTE_KEY in loaded:
        raise ConfigFileError(
            f"{source}: sets {YTE_KEY}: Snakemake would evaluate the file's ?-expressions as Python when it loads it. "
            "A siloflow configuration is plain data: remove the key and write the values out")
    try:
        _refuse_ambiguous_booleans(loaded, "", set())
    except ConfigFileError as error:
        raise ConfigFileError(f"{source}: {error}") from None
    return loaded


def read_config_file(path: str | Path) -> dict:
    """Read a configuration file with :func:`load_config_text`.

    Raises
    ------
    ConfigFileError
        As :func:`load_config_text`, or when the file is larger than :data:`MAX_BYTES` or is not UTF-8 text.
    FileNotFoundError
        When there is no such file.
    """
    path = Path(path)
    if path.stat().st_size > MAX_BYTES:
        raise ConfigFileError(f"{path}: larger than {MAX_BYTES:,} bytes; a configuration is a few kilobytes")
    try:
        text = path.read_text(encoding="utf-8")
    except UnicodeDecodeError:
        raise ConfigFileError(f"{path}: not UTF-8 text") from None
    return load_config_text(text, str(path))
