"""The flat-bottom silo case derived from configuration: counts, zones, steps, run ids."""

from __future__ import annotations

import copy
import hashlib
import json
import math

import pytest

from siloflow.engines.config import validate_config
from siloflow.model.cases.config_checks import ConfigError
from siloflow.model.cases.common import material_table, run_id
from siloflow.model.rolling import ROLLING_LAW
from siloflow.model.cases import case_for_run
from siloflow.model.cases.silo_flat import build_silo_case


def test_clump_count_follows_the_fill_height(tiny_config):
    case = build_silo_case(tiny_config)
    silo = tiny_config["silo_flat"]
    expected = 667.0 * silo["width"] * silo["depth"] * silo["fill_height"] / case.particle.mass
    assert case.fill.n_clumps == round(expected)


def test_sphere2_clump_mass_is_two_spheres_minus_their_lens(tiny_config):
    # two r = 1.5 mm spheres, centres d = 0.75 mm apart: V = 2 (4/3) pi r^3 - pi (4r + d)(2r - d)^2 / 12
    r, d = 1.5e-3, 0.75e-3
    volume = 2 * 4 / 3 * math.pi * r**3 - math.pi * (4 * r + d) * (2 * r - d) ** 2 / 12
    case = build_silo_case(tiny_config)
    assert case.particle.volume == pytest.approx(volume, rel=1e-12)
    assert case.particle.mass == pytest.approx(950.0 * volume, rel=1e-12)
    assert case.particle.bounding_radius == pytest.approx(r + d / 2, rel=1e-12)


def test_insertion_zone_lies_above_the_heap_and_inside_the_walls(tiny_config):
    case = build_silo_case(tiny_config)
    x_min, x_max, y_min, y_max, z_min, z_max = case.fill.zone
    heap_top = case.fill_height + 0.5 * case.width * math.tan(math.radians(40.0))
    assert z_min == pytest.approx(heap_top + 4 * case.particle.bounding_radius, rel=1e-12)
    assert -case.width / 2 < x_min < x_max < case.width / 2
    # the zone spans the depth; all_in keeps the clumps' bounding spheres off the front and back walls
    assert (y_min, y_max) == (0.0, case.depth)
    assert case.domain_top > z_max


def test_a_silo_one_clump_thick_still_has_an_insertion_zone(tiny_config):
    tiny_config["silo_flat"]["depth"] = 0.0045  # one 3.75 mm clump
    x_min, x_max, y_min, y_max, _, _ = build_silo_case(tiny_config).fill.zone
    assert (y_min, y_max) == (0.0, 0.0045)


def test_insertion_events_do_not_overlap(tiny_config):
    case = build_silo_case(tiny_config)
    zone_height = case.fill.zone[5] - case.fill.zone[4]
    # a batch falls from the insertion velocity: it has left the zone when the next one comes, and not a step later
    def fallen(steps):
        t = steps * case.timestep
        return case.fill.insertion_velocity * t + 0.5 * 9.81 * t**2
    assert fallen(case.fill.insert_every) >= zone_height > fallen(case.fill.insert_every - 1)
    assert case.fill.fill_steps * case.timestep * case.fill.particle_rate >= case.fill.n_clumps


def test_time_step_is_the_rayleigh_limit_when_impacts_are_slow(tiny_config):
    tiny_config["silo_flat"]["timestep_fraction"] = 0.1   # at 0.2 the tiny silo's fast pour makes Hertz bind
    case = build_silo_case(tiny_config)
    choice = case.timestep_choice
    # the fastest impact: a clump leaving the top of the domain at the insertion velocity falls onto the fill
    fall = case.domain_top - case.fill_height
    assert choice.impact_velocity == pytest.approx(math.sqrt(case.fill.insertion_velocity**2 + 2 * 9.81 * fall), rel=1e-12)
    assert choice.limited_by == "rayleigh"
    assert case.timestep == pytest.approx(0.1 * choice.rayleigh_time, rel=1e-12)
    assert case.summary()["timestep_limited_by"] == "rayleigh"


def test_time_step_is_the_hertz_limit_when_the_rayleigh_fraction_is_loose(tiny_config):
    tiny_config["silo_flat"]["timestep_fraction"] = 0.5
    tiny_config["silo_flat"]["timestep_hertz_fraction"] = 0.05
    choice = build_silo_case(tiny_config).timestep_choice
    assert choice.limited_by == "hertz"
    assert choice.timestep == pytest.approx(0.05 * choice.hertz_time, rel=1e-12)


def test_the_pour_is_gentle_its_momentum_flux_on_the_finished_fill_stays_below_the_set_share_of_the_weight(tiny_config):
    tiny_config["silo_flat"]["fill"]["momentum_flux_ratio"] = 0.05
    case = build_silo_case(tiny_config)
    fill, particle, g = case.fill, case.particle, 9.81
    # free fall from the zone's floor to the fill height, starting at the insertion velocity
    impact = math.sqrt(fill.insertion_velocity**2 + 2 * g * (fill.zone[4] - case.fill_height))
    assert fill.impact_velocity == pytest.approx(impact, rel=1e-12)
    flux_ratio = fill.particle_rate * particle.mass * impact / (fill.n_clumps * particle.mass * g)
    assert fill.momentum_flux_ratio == pytest.approx(flux_ratio, rel=1e-12)
    assert flux_ratio <= 0.05
    # one clump more per insertion event would exceed it: the planner keeps the largest gentle batch
    faster = (fill.clumps_per_insertion + 1) / (fill.insert_every * case.timestep)
    assert faster * particle.mass * impact / (fill.n_clumps * particle.mass * g) > 0.05


def test_a_loose_flux_limit_leaves_the_batches_the_zone_holds(tiny_config):
    tiny_config["silo_flat"]["fill"]["momentum_flux_ratio"] = 100.0
    loose = build_silo_case(tiny_config).fill
    tiny_config["silo_flat"]["fill"]["momentum_flux_ratio"] = 0.01
    gentle = build_silo_case(tiny_config).fill
    assert gentle.clumps_per_insertion < loose.clumps_per_insertion
    assert gentle.insert_every == loose.insert_every and gentle.fill_steps > loose.fill_steps


def test_material_types_put_the_particle_first():
    config = validate_config({})
    table = material_table(config, "hdpe", ["aluminium", "aluminium", "perspex"])
    assert table.names == ("hdpe", "aluminium", "perspex")
    assert table.type_of("perspex") == 3
    assert table.sliding_friction[0] == (0.35, 0.17, 0.2)
    assert table.sliding_friction[1][2] == 0.0  # aluminium-perspex never touch: neutral value


def test_run_id_is_stable_and_changes_with_any_defining_parameter(tiny_config):
    case = build_silo_case(tiny_config)
    assert case.run_id == build_silo_case(copy.deepcopy(tiny_config)).run_id
    assert case.run_id.startswith("sphere2-")
    changed = copy.deepcopy(tiny_config)
    changed["contacts"][0]["rolling_friction"] = 0.2
    assert build_silo_case(changed).run_id != case.run_id
    # analysis-only settings do not define the simulation
    analysis_only = copy.deepcopy(tiny_config)
    analysis_only["silo_flat"]["steady_window"] = [0.1, 0.9]
    analysis_only["silo_flat"]["fields"]["average_window"] = [0.5, 0.7]
    assert build_silo_case(analysis_only).run_id == case.run_id


def test_the_fields_averaging_window_must_lie_within_the_discharge():
    # discharge_time 3 s by default: the study's 0.5-0.7 s and the whole discharge pass
    for window in ([0.5, 0.7], [0.0, 3.0]):
        assert validate_config({"silo_flat": {"fields": {"average_window": window}}})["silo_flat"]["fields"][
            "average_window"] == window
    for window in ([0.5, 3.5], [0.7, 0.5], [0.5, 0.5]):
        with pytest.raises(ConfigError, match=r"config key 'silo_flat.fields.average_window': \[.*\] s must be an "
                                              r"increasing window within the discharge.*discharge_time \(3.0 s\)"):
            validate_config({"silo_flat": {"fields": {"average_window": window}}})
    # a longer discharge holds a later window
    longer = validate_config({"silo_flat": {"discharge_time": 4.0, "fields": {"average_window": [0.5, 3.5]}}})
    assert longer["silo_flat"]["fields"]["average_window"] == [0.5, 3.5]


def test_contact_pair_order_does_not_change_the_run_id(tiny_config):
    swapped = copy.deepcopy(tiny_config)
    swapped["contacts"][1]["materials"] = list(reversed(swapped["contacts"][1]["materials"]))
    assert build_silo_case(swapped).run_id == build_silo_case(tiny_config).run_id


def test_run_id_hash_by_hand():
    # the first ten hex digits of the SHA-256 of the canonical JSON, the rolling law included
    canonical = json.dumps({"a": 1, "rolling_law": ROLLING_LAW}, sort_keys=True, separators=(",", ":"))
    assert run_id("x", {"a": 1}) == "x-" + hashlib.sha256(canonical.encode()).hexdigest()[:10] == "x-2403c2ea57"


def test_unknown_run_is_reported_with_the_defined_ones(tiny_config):
    with pytest.raises(KeyError, match="defines: sphere2-"):
        case_for_run(tiny_config, "silo_flat", "sphere2-0000000000")


@pytest.mark.parametrize(
    "key, value, message",
    [
        ("depth", 0.002, "depth .* is thinner than one clump"),
        ("sink_depth", 0.001, "sink_depth .* must exceed one clump size"),
    ],
)
def test_inconsistent_geometry_is_refused(tiny_config, key, value, message):
    # an outlet wider than the silo is refused where the configuration is validated (test_config)
    config = copy.deepcopy(tiny_config)
    config["silo_flat"][key] = value
    with pytest.raises(ValueError, match=message):
        build_silo_case(config)

