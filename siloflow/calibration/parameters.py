"""Chosen particle-scale parameters: from the inverted calibration chart into a silo or blender config.

``results/calibration/parameters.yaml`` holds the output of :func:`siloflow.calibration.inversion.invert_calibration`
(plain data). :func:`apply_calibrated_parameters` puts it into a configuration, so that a silo run with
``parameters: calibrated`` uses the particle model, sliding and rolling friction the calibration chose.
"""

from __future__ import annotations

import copy

import yaml


def apply_calibrated_parameters(config: dict, parameters: dict, particle_material: str) -> dict:
    """A copy of ``config`` whose contacts carry the calibrated particle-scale parameters.

    Replaced: the particle model of ``silo_flat``; the sliding and rolling friction of the particle-particle
    contact; for every wall material in ``parameters["particle_wall"]``, the sliding friction of the
    particle-wall contact and its rolling friction. Contacts of walls that were not calibrated keep their
    configured sliding friction but take the calibrated rolling friction, since rolling resistance is a
    property of the particle shape in the CDT model.

    Parameters
    ----------
    config : dict
        A validated configuration.
    parameters : dict
        The calibration result: ``shape``, ``rolling_friction``, ``particle_particle.sliding_friction`` and
        ``particle_wall.<material>.sliding_friction`` (dimensionless coefficients).
    particle_material : str
        The particle material whose contacts are replaced.

    Raises
    ------
    ValueError
        If the parameters lack the particle-particle result.
    """
    if "particle_particle" not in parameters:
        reason = parameters.get("unreachable", {}).get("internal", "was the internal test run?")
        raise ValueError(f"the calibration chose no particle-particle friction: {reason}")
    calibrated = copy.deepcopy(config)
    calibrated["silo_flat"]["particle_model"] = parameters["shape"]
    rolling = float(parameters["rolling_friction"])
    walls = parameters.get("particle_wall", {})
    for contact in calibrated["contacts"]:
        pair = list(contact["materials"])
        if particle_material not in pair:
            continue
        other = pair[1] if pair[0] == particle_material else pair[0]
        if other == particle_material:
            contact["sliding_friction"] = float(parameters["particle_particle"]["sliding_friction"])
            contact["rolling_friction"] = rolling
        elif other in walls:
            contact["sliding_friction"] = float(walls[other]["sliding_friction"])
            contact["rolling_friction"] = rolling
        elif other != config["jenike"]["lid_material"]:
            contact["rolling_friction"] = rolling
    return calibrated


#: The ``silo_flat.parameters`` that take a calibration's choice: the chart inversion's (``calibrated``) or the joint
#: Bayesian calibration's posterior mean on the silo's engine (``bayesian``); both files have the same layout.
CALIBRATED_SOURCES = ("calibrated", "bayesian")


def calibrated_config(config: dict, parameters_path) -> dict:
    """The configuration a silo run uses: as given, or with ``parameters: calibrated`` (or ``bayesian``) the
    calibration's choice.

    Reads ``parameters_path`` (YAML) only when ``silo_flat.parameters`` is one of :data:`CALIBRATED_SOURCES`.
    """
    if config["silo_flat"]["parameters"] not in CALIBRATED_SOURCES:
        return config
    with open(parameters_path, encoding="utf-8") as handle:
        parameters = yaml.safe_load(handle)
    return apply_calibrated_parameters(config, parameters, config["silo_flat"]["particle_material"])


def posterior_draw_configs(config: dict, draws: list[dict]) -> list[tuple[str, dict]]:
    """The configurations of a silo run at each posterior draw (``silo_flat.posterior_draws``): ``[(label, config)]``,
    labelled ``draw 0``, ``draw 1``, ..., each ``config`` with one draw's parameters (the layout of
    ``parameters.yaml``, :func:`siloflow.calibration.bayes.joint.draw_estimates`) in place of its contacts'."""
    material = config["silo_flat"]["particle_material"]
    return [(f"draw {number}", apply_calibrated_parameters(config, draw, material)) for number, draw in enumerate(draws)]
