"""Blender geometry: insert plates solved from the study's area ratios, levels, passages and bad input."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from siloflow.model.cases.blender_geometry import INSERT_PRESETS, blender_geometry
from siloflow.model.cases.blender_passages import annulus_bounds, clear_widths, geometry_summary
from siloflow.model.cases.blender_meshes import blender_meshes

# The study's full scale (thesis ch. 7).
FULL = dict(width=0.45, depth=0.04, vertical_height=1.5, hopper_half_angle=30.0, outlet_width=0.04,
            wall_thickness=0.005, tube_width=0.04, tube_inlet_above_transition=0.15 * 0.45)
TAN30 = math.tan(math.radians(30.0))
TARGETS = {"diverging": (0.5, 2.6, 5.2), "straight": (1.0, 1.72, 1.72), "converging": (2.0, 1.18, 0.59)}
INSERTS = ("diverging", "straight", "converging")


def full(insert="diverging", **changes):
    return blender_geometry(**{**FULL, **changes}, insert=insert)


# ------------------------------------------------------------------------------------------------ silo basics
def test_hopper_levels_follow_from_width_outlet_and_angle():
    g = full()
    # W/2 - b = 0.205 m, tan 30 = 1/sqrt(3): z_t = 0.205 sqrt(3); apex -0.02 sqrt(3); R = 0.225 / sin 30
    assert g.half_outlet == pytest.approx(0.02, rel=1e-15)
    assert g.z_transition == pytest.approx(0.205 * math.sqrt(3.0), rel=1e-12)
    assert g.z_apex == pytest.approx(-0.02 * math.sqrt(3.0), rel=1e-12)
    assert g.circle_radius == pytest.approx(0.45, rel=1e-12)
    assert g.z_top == pytest.approx(0.205 * math.sqrt(3.0) + 1.5, rel=1e-12)
    np.testing.assert_allclose(g.wall_x([0.0, 0.1, g.z_transition, 1.0]), [0.02, 0.02 + 0.1 * TAN30, 0.225, 0.225])


# ------------------------------------------------------------------------------------------------ insert presets
@pytest.mark.parametrize("preset", INSERTS)
def test_presets_achieve_their_area_ratios(preset):
    g = full(preset)
    interior, exterior, ratio = TARGETS[preset]
    assert INSERT_PRESETS[preset] == {"interior_ratio": interior, "exterior_ratio": exterior}
    assert g.interior_ratio == pytest.approx(interior, rel=1e-12)
    assert g.exterior_ratio == pytest.approx(exterior, rel=1e-12)
    assert g.area_ratio == pytest.approx(ratio, rel=1e-12)


@pytest.mark.parametrize("preset", INSERTS)
def test_preset_inlet_lies_on_the_circle_about_the_apex_above_the_transition(preset):
    g = full(preset)
    x_i, z_i = g.insert_inlet
    assert x_i**2 + (z_i - g.z_apex) ** 2 == pytest.approx(g.circle_radius**2, rel=1e-12)
    assert g.z_transition <= z_i
    assert g.wall_x(z_i) == 0.225


def test_presets_share_the_outlet_level_fixed_by_the_diverging_occupancy():
    # X = (W/2 - tw (1 - 0.5)) / (0.63 * 0.5 + 0.37 * 2.6) = 0.215 / 1.277; z_o = (X - b) / tan 30
    wall = 0.215 / 1.277
    z_o = (wall - 0.02) / TAN30
    levels = {preset: full(preset).insert_outlet[1] for preset in INSERTS}
    assert levels == pytest.approx({preset: z_o for preset in INSERTS}, rel=1e-12)
    assert full("diverging").insert_occupancy == pytest.approx(0.63, rel=1e-12)
    assert full("diverging").insert_outlet[0] == pytest.approx(0.63 * wall, rel=1e-12)
    # the tube outlet is the insert outlet, also without an insert
    assert full(None).z_tube_outlet == pytest.approx(z_o, rel=1e-12)


def test_preset_end_points_match_the_study_numbers():
    diverging = full("diverging")
    assert diverging.insert_inlet == pytest.approx((0.0630, 0.4109), abs=1e-4)
    assert diverging.insert_outlet == pytest.approx((0.1061, 0.2570), abs=1e-4)
    straight = full("straight")
    assert straight.insert_inlet[0] == pytest.approx(straight.insert_outlet[0], rel=1e-12)
    assert straight.insert_outlet[0] == pytest.approx(0.0897, abs=1e-4)
    converging = full("converging")
    assert converging.insert_outlet[0] == pytest.approx(0.0565, abs=1e-4)
    assert converging.insert_inlet[0] == pytest.approx(0.0930, abs=1e-4)


def test_included_angle_between_plate_and_hopper_wall():
    # a vertical (straight) plate meets the 30 degree hopper wall at exactly 30 degrees
    assert full("straight").included_angle == pytest.approx(30.0, rel=1e-12)
    g = full("diverging")
    (x_i, z_i), (x_o, z_o) = g.insert_inlet, g.insert_outlet
    cosine = ((x_i - x_o) * 0.5 + (z_i - z_o) * math.sqrt(3.0) / 2.0) / math.hypot(x_i - x_o, z_i - z_o)
    assert g.included_angle == pytest.approx(math.degrees(math.acos(cosine)), rel=1e-12)
    assert g.included_angle == pytest.approx(45.6, abs=0.05)  # the study states about 44


def test_plate_end_points_given_directly_give_back_their_ratios():
    g = full({"inlet": [0.07, 0.40], "outlet": [0.10, 0.26]})
    assert g.insert_inlet == (0.07, 0.40)
    assert g.insert_outlet == (0.10, 0.26)
    assert g.insert_name == "custom"
    assert g.interior_ratio == pytest.approx((0.07 - 0.02) / (0.10 - 0.02), rel=1e-12)
    exterior = (0.225 - 0.07) / (0.02 + 0.26 * TAN30 - 0.10)
    assert g.exterior_ratio == pytest.approx(exterior, rel=1e-12)
    assert g.area_ratio == pytest.approx(exterior / 0.625, rel=1e-12)
    assert g.z_tube_outlet == 0.26


def test_ratios_given_as_a_dict_solve_like_the_preset():
    custom = full({"interior_ratio": 0.5, "exterior_ratio": 2.6})
    preset = full("diverging")
    assert custom.insert_inlet == preset.insert_inlet
    assert custom.insert_outlet == preset.insert_outlet


def test_preset_none_has_neither_insert_nor_tube():
    g = full("none")
    assert not g.has_insert and not g.has_tube
    assert list(blender_meshes(g)) == ["hopper_left", "hopper_right"]
    assert clear_widths(g) == {"outlet": 0.04}
    assert annulus_bounds(g, 0.3) == {"open": (0.0, 0.02 + 0.3 * TAN30)}


def test_geometry_summary_is_plain_data():
    summary = geometry_summary(full("diverging"))
    assert json.loads(json.dumps(summary)) == summary
    assert summary["interior_ratio"] == pytest.approx(0.5, rel=1e-12)
    assert summary["exterior_ratio"] == pytest.approx(2.6, rel=1e-12)
    assert summary["area_ratio"] == pytest.approx(5.2, rel=1e-12)
    assert summary["occupancy"] == pytest.approx(0.63, rel=1e-12)
    assert summary["z_tube_inlet"] == pytest.approx(0.205 * math.sqrt(3.0) + 0.0675, rel=1e-12)
    assert summary["z_tube_outlet"] == summary["z_insert_outlet"] == summary["outlet"][1]
    none = geometry_summary(full("none"))
    assert none["inlet"] is None and none["z_tube_inlet"] is None


def test_internal_wall_spans_are_plate_and_tube_mid_lines():
    g = full("diverging")
    assert g.internal_wall_spans() == [
        (g.insert_outlet, g.insert_inlet),
        ((0.02, g.z_tube_outlet), (0.02, g.z_tube_inlet)),
    ]


# ------------------------------------------------------------------------------------------------ passages
def test_annulus_bounds_tile_the_half_width_minus_the_walls():
    g = full("diverging")
    t = 0.005
    (x_i, z_i), (x_o, z_o) = g.insert_inlet, g.insert_outlet
    # horizontal cut through the inclined plate: t / cos(beta), cos(beta) = dz / length
    plate_cut = t * math.hypot(x_i - x_o, z_i - z_o) / (z_i - z_o)
    for z in (0.30, 0.38):  # in the hopper, and above the transition (both within the insert and the tube)
        bounds = annulus_bounds(g, z)
        assert list(bounds) == ["tube", "interior", "exterior"]
        (tube_lo, tube_hi), (int_lo, int_hi), (ext_lo, ext_hi) = bounds.values()
        x_plate = x_o + (z - z_o) * (x_i - x_o) / (z_i - z_o)
        assert tube_lo == 0.0 and tube_hi == pytest.approx(0.02 - t / 2, rel=1e-12)
        assert int_lo - tube_hi == pytest.approx(t, rel=1e-12)  # the tube plate
        assert ext_lo - int_hi == pytest.approx(plate_cut, rel=1e-12)  # the insert plate
        assert (int_hi + ext_lo) / 2 == pytest.approx(x_plate, rel=1e-12)
        assert ext_hi == pytest.approx(min(0.02 + z * TAN30, 0.225), rel=1e-12)
        widths = sum(hi - lo for hi, lo in [(tube_hi, tube_lo), (int_hi, int_lo), (ext_hi, ext_lo)])
        assert widths + t + plate_cut == pytest.approx(ext_hi, rel=1e-12)


def test_annulus_bounds_away_from_the_insert_are_open():
    g = full("diverging")
    assert annulus_bounds(g, 0.1) == {"open": (0.0, pytest.approx(0.02 + 0.1 * TAN30, rel=1e-12))}
    between = 0.5 * (g.insert_inlet[1] + g.z_tube_inlet)  # above the insert, inside the tube
    assert annulus_bounds(g, between) == {"tube": (0.0, 0.0175), "open": (0.0225, 0.225)}
    assert annulus_bounds(g, 1.0) == {"open": (0.0, 0.225)}


def test_clear_widths_of_the_diverging_insert():
    g = full("diverging")
    t = 0.005
    (x_i, z_i), (x_o, z_o) = g.insert_inlet, g.insert_outlet
    half_cut = 0.5 * t * math.hypot(x_i - x_o, z_i - z_o) / (z_i - z_o)
    widths = clear_widths(g)
    assert widths["outlet"] == 0.04
    assert widths["tube"] == pytest.approx(0.04 - t, rel=1e-12)
    # the diverging insert is narrowest inside at its inlet and outside at its outlet
    assert widths["interior annulus"] == pytest.approx(x_i - half_cut - 0.02 - t / 2, rel=1e-12)
    assert widths["exterior annulus"] == pytest.approx(0.215 / 1.277 - x_o - half_cut, rel=1e-12)


# ------------------------------------------------------------------------------------------------ bad input
@pytest.mark.parametrize(
    "changes, insert, message",
    [
        ({"wall_thickness": -0.005}, "diverging", "wall_thickness"),
        ({"hopper_half_angle": 90.0}, "diverging", "hopper_half_angle"),
        ({"tube_inlet_above_transition": -0.2}, "diverging", "tube_inlet_above_transition"),
        ({"tube_inlet_above_transition": -0.2}, None, "tube_inlet_above_transition"),
        ({"tube_width": 0.004}, "diverging", "tube_width"),
        ({}, {"interior_ratio": 1.3, "exterior_ratio": 1.3}, "exterior_ratio=1.3 equals interior_ratio=1.3"),
        ({}, {"inlet": [0.30, 0.50], "outlet": [0.10, 0.26]}, "insert inlet is outside the silo"),
        ({}, {"inlet": [0.07, 0.40], "outlet": [0.168, 0.26]}, "insert outlet is outside the silo"),
        ({}, {"inlet": [0.07, 2.00], "outlet": [0.10, 0.26]}, "insert inlet lies above the top"),
        ({}, {"inlet": [0.07, 0.20], "outlet": [0.10, 0.26]}, "insert outlet must lie below the insert inlet"),
        ({}, {"inlet": [0.024, 0.40], "outlet": [0.10, 0.26]}, "tube mid-line"),
        ({}, {"interior_ratio": 0.1, "exterior_ratio": 0.2}, "insert interior_ratio=0.1, exterior_ratio=0.2"),
        ({}, "funnel", "insert must be one of"),
        ({}, {"inlet": [0.07, 0.40]}, "insert dict needs"),
        ({"occupancy": 1.2}, "diverging", "occupancy"),
    ],
)
def test_bad_input_names_the_parameter(changes, insert, message):
    with pytest.raises(ValueError, match=message.replace("(", r"\(").replace(".", r"\.")):
        full(insert, **changes)


def test_bad_levels_and_a_missing_insert_are_rejected():
    g = full("diverging")
    with pytest.raises(ValueError, match="z must lie within"):
        annulus_bounds(g, -0.01)
    with pytest.raises(ValueError, match="z must lie within"):
        g.wall_x(g.z_top + 0.01)
    with pytest.raises(ValueError, match="no insert"):
        full("none").plate_x(0.3)
