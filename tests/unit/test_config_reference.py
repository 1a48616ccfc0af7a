"""The configuration reference page: generated from the schema, exact on a small schema, and the committed page is
what the real schema gives (so that it cannot go stale)."""

from __future__ import annotations

import copy

import pytest

from siloflow.engines.config import load_schema
from siloflow.engines.config_reference import (REGENERATE, keys_lacking_description_or_default, main,
                                               render_reference, schema_keys, unit_of)
from tests.repo import REPO_ROOT

REFERENCE_PAGE = REPO_ROOT / "docs" / "configuration-reference.md"

#: A small configuration schema with each construct the real one uses: nested objects, $ref into `definitions` and
#: `$defs`, an enum, oneOf, a map (additionalProperties) and a list of objects, units in the descriptions.
SYNTHETIC = {
    "description": "A test configuration.",
    "definitions": {"length": {"description": "A length (m).", "type": "number", "exclusiveMinimum": 0}},
    "$defs": {"speed": {"description": "A speed (m/s).", "type": "number", "default": 1.0}},
    "type": "object",
    "properties": {
        "pipe": {
            "description": "The pipe.", "type": "object", "default": {},
            "properties": {
                "length": {"$ref": "#/definitions/length", "description": "Pipe length (m).", "default": 2.0},
                "inlet": {
                    "description": "The inlet.", "type": "object", "default": {},
                    "properties": {
                        "speed": {"$ref": "#/$defs/speed"},
                        "shape": {"description": "Cross-section.", "enum": ["round", "square"], "default": "round"},
                    },
                },
                "diameter": {"description": "Diameter (m); null takes a tenth of the length.",
                             "oneOf": [{"type": "null"}, {"$ref": "#/definitions/length"}], "default": None},
            },
        },
        "fluids": {
            "description": "Fluids by name.", "type": "object", "default": {"water": {"density": 1000.0}},
            "additionalProperties": {
                "type": "object", "required": ["density"],
                "properties": {
                    "density": {"description": "Density (kg/m3).", "type": "number"},
                    "colour": {"description": "Colour in plots (a <name> of matplotlib | a hex code).",
                               "type": "string"},
                },
            },
        },
        "probes": {
            "description": "Probes along the pipe.", "type": "array", "default": [],
            "items": {"type": "object",
                      "properties": {"position": {"description": "Distance from the inlet (m).", "type": "number"}}},
        },
    },
}


def _table_rows(page: str) -> list[str]:
    return [line for line in page.splitlines() if line.startswith("| `")]


def test_every_key_of_a_small_schema_is_listed_with_its_path():
    assert [key.path for key in schema_keys(SYNTHETIC)] == [
        "pipe", "pipe.length", "pipe.inlet", "pipe.inlet.speed", "pipe.inlet.shape", "pipe.diameter",
        "fluids", "fluids.<name>.density", "fluids.<name>.colour", "probes", "probes[].position",
    ]


def test_a_small_schema_gives_exact_rows_per_section():
    page = render_reference(SYNTHETIC)
    assert [line for line in page.splitlines() if line.startswith("## ")] == ["## pipe", "## fluids", "## probes"]
    assert "Type: object. Default: `{}`." in page  # the section's own entry, above its table
    assert "Type: map of name to object. Default: `{water: {density: 1000.0}}`." in page
    assert "Type: array of object. Default: `[]`." in page
    assert _table_rows(page) == [
        "| `pipe.length` | number | m | `2.0` | Pipe length (m). |",
        "| `pipe.inlet` | object |  | `{}` | The inlet. |",
        "| `pipe.inlet.speed` | number | m/s | `1.0` | A speed (m/s). |",  # all from its $defs definition
        "| `pipe.inlet.shape` | one of: `round`, `square` |  | `round` | Cross-section. |",
        "| `pipe.diameter` | null or number | m | `null` | Diameter (m); null takes a tenth of the length. |",
        "| `fluids.<name>.density` | number | kg/m^3 | required | Density (kg/m3). |",
        # Markdown's markup in prose is escaped: a | would end the cell, <name> would be an HTML tag
        "| `fluids.<name>.colour` | string |  |  | Colour in plots (a &lt;name> of matplotlib \\| a hex code). |",
        "| `probes[].position` | number | m |  | Distance from the inlet (m). |",
    ]


def test_long_defaults_are_written_as_yaml_below_the_table():
    schema = copy.deepcopy(SYNTHETIC)
    positions = [{"position": round(0.1 * index, 1)} for index in range(8)]
    schema["properties"]["probes"]["default"] = positions
    page = render_reference(schema)
    assert "Type: array of object. Default:\n\n```yaml\nprobes:\n- {position: 0.0}\n" in page


@pytest.mark.parametrize("description, unit", [
    ("Downward velocity of inserted clumps (m/s). At most 100 m/s.", "m/s"),
    ("Solid density (kg/m3), for dumps without a mass field.", "kg/m^3"),
    ("Poisson ratio (-), in (0, 0.5).", "-"),
    ("A parameter's prior (coefficients, -).", "-"),
    ("Two or more markers, each its image position (px, rows down).", "px"),
    ("Time windows [start, end] (s after the outlet opened).", "s"),
    ("Camera frame rates (1/s).", "1/s"),
    ("Neighbours up to this many nodes away (1, a 3 x 3 window).", ""),
    ("Time windows over (x, z) of the fields.", ""),
    ("Runs per engine (seeds silo_flat.seed, +1, ...).", ""),
])
def test_the_unit_is_read_from_the_description(description, unit):
    assert unit_of(description) == unit


def test_only_quantities_get_a_unit():
    schema = {"properties": {"units": {
        "description": "pixels or metres (m, m/s, silo coordinates with z up).", "enum": ["pixels", "metres"],
        "default": "pixels"}}}
    assert "| `units` |" not in render_reference(schema)  # a section: no table
    assert schema_keys(schema)[0].path == "units"
    nested = {"properties": {"piv": {"description": "PIV.", "type": "object", "default": {},
                                     "properties": {"units": schema["properties"]["units"]}}}}
    assert _table_rows(render_reference(nested)) == [
        "| `piv.units` | one of: `pixels`, `metres` |  | `pixels` | pixels or metres (m, m/s, silo coordinates "
        "with z up). |"]


def test_a_recursive_ref_is_listed_once():
    schema = {"definitions": {"node": {"type": "object", "properties": {
        "child": {"$ref": "#/definitions/node", "description": "A child.", "default": {}}}}},
        "properties": {"tree": {"$ref": "#/definitions/node", "description": "A tree.", "default": {}}}}
    assert [key.path for key in schema_keys(schema)] == ["tree", "tree.child"]


def test_keys_lacking_a_description_or_a_default_are_reported():
    assert keys_lacking_description_or_default(SYNTHETIC) == []  # a map's entries and a list's items are exempt
    schema = copy.deepcopy(SYNTHETIC)
    pipe = schema["properties"]["pipe"]["properties"]
    pipe["roughness"] = {"type": "number", "default": 0.0}
    pipe["material"] = {"description": "Wall material.", "type": "string"}
    pipe["inlet"]["properties"]["swirl"] = {"type": "number"}
    assert keys_lacking_description_or_default(schema) == [
        ("pipe.inlet.swirl", ("description", "default")),
        ("pipe.roughness", ("description",)),
        ("pipe.material", ("default",)),
    ]


def test_every_key_of_the_real_schema_has_a_description_and_a_default():
    assert keys_lacking_description_or_default(load_schema()) == []


def test_the_committed_reference_page_is_what_the_schema_gives():
    expected = render_reference(load_schema())
    assert REFERENCE_PAGE.read_text(encoding="utf-8") == expected, (
        f"{REFERENCE_PAGE.relative_to(REPO_ROOT)} is not what the schema gives: regenerate it with "
        f"`.venv/bin/{REGENERATE}` and commit it")


def test_main_writes_the_page(tmp_path):
    output = tmp_path / "reference.md"
    assert main([str(output)]) == 0
    assert output.read_text(encoding="utf-8") == render_reference(load_schema())


def test_main_refuses_a_path_it_cannot_write_in_one_line(tmp_path, capsys):
    assert main([str(tmp_path / "missing" / "reference.md")]) == 2
    error = capsys.readouterr().err
    assert error.count("\n") == 1 and "cannot write" in error and "missing" in error


def test_main_has_help(capsys):
    with pytest.raises(SystemExit) as exit_:
        main(["--help"])
    assert exit_.value.code == 0
    assert "output" in capsys.readouterr().out
