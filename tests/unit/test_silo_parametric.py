"""Parametric silo studies: one extra run per value, differing from the base run in one respect."""

from __future__ import annotations

import copy

from siloflow.engines.liggghts.silo_flat import render_silo_deck
from siloflow.model.cases.silo_flat import build_silo_case, parametric_variants, silo_cases


def _contact(config, a, b):
    return next(c for c in config["contacts"] if sorted(c["materials"]) == sorted([a, b]))


def test_no_study_means_only_the_base_run(tiny_config):
    assert parametric_variants(tiny_config) == {}
    assert list(silo_cases(tiny_config)) == [build_silo_case(tiny_config).run_id]


def test_front_back_friction_gets_its_own_wall_material(tiny_config):
    config = copy.deepcopy(tiny_config)
    config["silo_flat"]["parametric"].update(front_back_friction=[0.0, 0.5], periodic_front_back=True)
    (study,) = parametric_variants(config).items()
    name, runs = study
    assert name == "front_back_friction"
    assert [label for label, _ in runs] == ["mu_fw=0", "mu_fw=0.5", "periodic"]
    variant = runs[1][1]
    wall = variant["silo_flat"]["wall_materials"]["front_back"]
    assert wall == "perspex_fw0500"
    assert _contact(variant, "hdpe", wall)["sliding_friction"] == 0.5
    # side walls keep their friction, the base config is untouched
    assert _contact(variant, "hdpe", "aluminium") == _contact(tiny_config, "hdpe", "aluminium")
    assert config["silo_flat"]["wall_materials"]["front_back"] == "perspex"
    assert len(silo_cases(config)) == 4


def test_periodic_variant_has_no_front_back_walls_and_a_periodic_depth(tiny_config):
    config = copy.deepcopy(tiny_config)
    config["silo_flat"]["parametric"]["periodic_front_back"] = True
    (_, periodic), = parametric_variants(config)["front_back_friction"]
    deck = render_silo_deck(build_silo_case(periodic))
    assert "boundary f p f" in deck
    assert "yplane" not in deck
    assert "xplane" in deck


def test_restitution_and_friction_studies(tiny_config):
    config = copy.deepcopy(tiny_config)
    config["silo_flat"]["parametric"].update(restitution=[0.6], sliding_friction=[0.15, 0.57], rolling_friction=[0.0, 0.2])
    studies = parametric_variants(config)
    (label, restitution), = studies["restitution"]
    assert label == "e=0.6"
    assert _contact(restitution, "hdpe", "hdpe")["restitution"] == 0.6
    assert _contact(restitution, "hdpe", "aluminium")["restitution"] == 0.6
    assert _contact(restitution, "hdpe", "lid") == _contact(config, "hdpe", "lid")
    labels = [label for label, _ in studies["friction"]]
    assert labels == ["mu=0.15,mu_r=0", "mu=0.15,mu_r=0.2", "mu=0.57,mu_r=0", "mu=0.57,mu_r=0.2"]
    _, last = studies["friction"][-1]
    assert _contact(last, "hdpe", "hdpe")["sliding_friction"] == 0.57
    assert _contact(last, "hdpe", "hdpe")["rolling_friction"] == 0.2
    assert _contact(last, "hdpe", "aluminium")["sliding_friction"] == _contact(config, "hdpe", "aluminium")["sliding_friction"]
    assert _contact(last, "hdpe", "aluminium")["rolling_friction"] == 0.2
    assert len(silo_cases(config)) == 1 + 1 + 4
