"""The configuration loader on hostile and ambiguous YAML: each refused naming the file and the key or line."""

from __future__ import annotations

import time

import pytest
import yaml

from siloflow.cli.main import main
from siloflow.engines.config_yaml import (
    MAX_ALIASES, MAX_BYTES, MAX_DEPTH, MAX_NODES, ConfigFileError, load_config_text, read_config_file,
)


def test_plain_data_is_read_as_yaml_reads_it():
    text = "a: 1\nb: [x, 'no', true, false, 2.5e-3]\nc: {d: null}\nbase: &base {k: 1}\nother: {<<: *base, m: 2}\n"
    assert load_config_text(text) == {"a": 1, "b": ["x", "no", True, False, 0.0025], "c": {"d": None},
                                      "base": {"k": 1}, "other": {"k": 1, "m": 2}}
    assert load_config_text("") == {}
    assert load_config_text("# only a comment\n") == {}


def test_a_file_that_asks_for_yte_is_refused_saying_why():
    text = "__use_yte__: true\nseed: ?1 + 1\n"
    with pytest.raises(ConfigFileError, match=r"^my.yaml: sets __use_yte__: Snakemake would evaluate the file's "
                                              r"\?-expressions as Python"):
        load_config_text(text, "my.yaml")


def test_a_duplicate_key_is_refused_naming_it_and_both_lines():
    with pytest.raises(ConfigFileError, match=r"^c.yaml: line 4: the key 'materials' is given twice \(first on line 1\)"):
        load_config_text("materials:\n  a: 1\nseed: 1\nmaterials:\n  b: 2\n", "c.yaml")
    with pytest.raises(ConfigFileError, match=r"line 3: the key 'x' is given twice \(first on line 2\)"):
        load_config_text("top:\n  x: 1\n  x: 2\n")


@pytest.mark.parametrize("word", ["no", "yes", "on", "off", "No", "YES", "On", "OFF"])
def test_a_yaml_1_1_boolean_word_is_refused_naming_its_key(word):
    with pytest.raises(ConfigFileError, match=rf"^c.yaml: config key 'silo_flat.particle_model' \(line 2\): "
                                              rf"'{word}' is a YAML 1.1 boolean; write true or false for a switch, "
                                              rf"or quote it \('{word}'\) for a name"):
        load_config_text(f"silo_flat:\n  particle_model: {word}\n", "c.yaml")
    with pytest.raises(ConfigFileError, match=rf"config key 'shapes\[1\]' \(line 1\): '{word}'"):
        load_config_text(f"shapes: [sphere, {word}]\n", "c.yaml")
    with pytest.raises(ConfigFileError, match=rf"line 2: the key '{word}' is a YAML 1.1 boolean; quote it"):
        load_config_text(f"materials:\n  {word}: {{density: 1.0}}\n", "c.yaml")
    # quoted, it is the name; true and false stay booleans
    assert load_config_text(f"name: '{word}'\nswitch: true\n") == {"name": word, "switch": True}


def _bomb(levels: int, width: int) -> str:
    """A billion-laughs document: each level a list of ``width`` aliases of the level below."""
    lines = ["a0: &a0 [" + ", ".join(["x"] * width) + "]"]
    for level in range(1, levels):
        lines.append(f"a{level}: &a{level} [" + ", ".join([f"*a{level - 1}"] * width) + "]")
    return "\n".join(lines) + "\n"


def test_an_alias_bomb_is_refused_at_once_by_its_expanded_size():
    # 9 levels of 10: 72 aliases (within the alias bound) that expand to over 10^9 values
    started = time.perf_counter()
    with pytest.raises(ConfigFileError, match=rf"^c.yaml: its aliases expand it to {MAX_NODES + 1:,} values, more "
                                              rf"than {MAX_NODES:,}"):
        load_config_text(_bomb(9, 9), "c.yaml")
    # expanded, it would hang for hours: an outcome within 10 s is no hang (not a speed: the machine's load moves it)
    assert time.perf_counter() - started < 10.0
    # a few levels stay readable: a2 is 3 lists of a1, each 3 lists of a0 = [x, x, x]
    assert load_config_text(_bomb(3, 3))["a2"] == [[["x"] * 3] * 3] * 3


def test_more_aliases_than_a_configuration_needs_are_refused():
    text = "a: &a 1\nb: [" + ", ".join(["*a"] * (MAX_ALIASES + 1)) + "]\n"
    with pytest.raises(ConfigFileError, match=rf"line 2: more than {MAX_ALIASES} aliases"):
        load_config_text(text)


def test_deep_nesting_is_refused_before_python_recurses_too_deep():
    with pytest.raises(ConfigFileError, match=rf"^c.yaml: line \d+: nested deeper than {MAX_DEPTH} levels"):
        load_config_text("a: " + "[" * 2_000 + "]" * 2_000 + "\n", "c.yaml")
    assert load_config_text("a: " + "[" * (MAX_DEPTH - 2) + "]" * (MAX_DEPTH - 2) + "\n")


def test_a_file_larger_than_a_configuration_and_what_is_not_a_mapping_are_refused(tmp_path):
    big = tmp_path / "big.yaml"
    big.write_text("a: " + "x" * MAX_BYTES + "\n")
    with pytest.raises(ConfigFileError, match=rf"big.yaml: larger than {MAX_BYTES:,} bytes"):
        read_config_file(big)
    with pytest.raises(ConfigFileError, match="the top level of a config file must be a mapping, got list"):
        load_config_text("- a\n- b\n")
    with pytest.raises(ConfigFileError, match="c.yaml: not valid YAML"):
        load_config_text("a: [1, 2\n", "c.yaml")
    binary = tmp_path / "binary.yaml"
    binary.write_bytes(b"a: \xff\xfe\n")
    with pytest.raises(ConfigFileError, match="binary.yaml: not UTF-8 text"):
        read_config_file(binary)


def test_the_shipped_configurations_read_as_before():
    for name in ("config/config.yaml", "config/validation.yaml", "config/thesis.yaml", "config/checks.yaml",
                 "config/bayesian_twin.yaml"):
        with open(name, encoding="utf-8") as handle:
            assert read_config_file(name) == yaml.safe_load(handle), name


def test_the_command_line_refuses_the_first_file_it_cannot_read_as_data(tmp_path, capsys):
    good = tmp_path / "good.yaml"
    good.write_text("seed: 1\n")
    asks = tmp_path / "asks.yaml"
    asks.write_text("__use_yte__: true\nseed: ?1 + 1\n")
    assert main(["check", "--config", str(good), "--config", str(asks)]) == 2
    assert capsys.readouterr().err == (f"siloflow check: invalid configuration: {asks}: sets __use_yte__: Snakemake "
                                       "would evaluate the file's ?-expressions as Python when it loads it. A "
                                       "siloflow configuration is plain data: remove the key and write the values "
                                       "out\n")
