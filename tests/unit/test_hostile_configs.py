"""Hostile and malformed configurations, each fed through the path `snakemake -n` takes when it parses the workflow
(``siloflow/workflow/rules/common.smk`` calls :func:`siloflow.engines.preflight.preflight`, then
:func:`siloflow.analysis.io.measured_inputs.check_measured_inputs`): every one is refused within a second, before any run
directory exists, with the offending key (or file line) named and no file's contents echoed.

Each configuration is a file laid over the default one, as ``snakemake --configfile config/config.yaml --configfile
hostile.yaml`` merges them; the file is also read again as plain data, as the workflow does.
"""

from __future__ import annotations

import time
from pathlib import Path

import pytest
import yaml
from snakemake.utils import update_config

from siloflow.engines.config import load_config_file
from tests.repo import REPO_ROOT
from siloflow.analysis.io.measured_inputs import MeasuredInputError, check_measured_inputs
from siloflow.engines.preflight import PreflightError, preflight

DEFAULT_CONFIG = REPO_ROOT / "config" / "config.yaml"

#: The longest a refusal may take (s).
REFUSAL_S = 1.0

#: Text found in the files the hostile configurations point readers at, which no message may repeat.
SECRET = "SECRET_TOKEN=hunter2"


def _bomb(levels: int = 9, width: int = 9) -> str:
    lines = ["a0: &a0 [x, x, x, x, x, x, x, x, x]"]
    for level in range(1, levels):
        lines.append(f"a{level}: &a{level} [{', '.join(f'*a{level - 1}' for _ in range(width))}]")
    return "\n".join(lines) + "\n"


def _nested(depth: int) -> str:
    return "silo_flat:\n  fields:\n    x: " + "[" * depth + "]" * depth + "\n"


#: (id, the file's text, what the message must contain). ``{tmp}`` is the test's folder, ``{secret}`` a file in it
#: holding :data:`SECRET`.
HOSTILE = [
    # the file itself: refused as data before the schema sees it
    ("yte", "__use_yte__: true\ndefaults:\n  seed: ?__import__('os').getpid()\n", "__use_yte__"),
    ("duplicate-section", "materials:\n  hdpe: {youngs_modulus: 5.0e+6, poisson_ratio: 0.4, density: 950.0}\n"
                          "materials: {}\n", "materials"),
    ("yaml11-boolean-name", "silo_flat:\n  particle_model: no\n", "silo_flat.particle_model"),
    ("yaml11-on", "blender:\n  particle_material: on\n", "blender.particle_material"),
    ("alias-bomb", _bomb(), "alias"),
    ("deep-nesting", _nested(200), "nest"),
    ("huge-file", "# " + "x" * 1_100_000 + "\ndefaults: {}\n", "larger than 1,000,000 bytes"),
    ("not-a-mapping", "- silo_flat\n- blender\n", "mapping"),
    ("not-utf8", "defaults:\n  seed: 1 # \xff\xfe\n", "UTF-8"),
    # numbers where an engine or the machine has a limit
    ("seed-trial-division", "defaults:\n  seed: 100000000000000\n", "defaults.seed"),
    ("seed-past-int32", "silo_flat:\n  seed: 2147483648\n", "silo_flat.seed"),
    ("replicates", "silo_flat:\n  replicates: 1000000\n", "silo_flat.replicates"),
    ("tiny-timestep", "jenike:\n  timestep_fraction: 1.0e-12\n", "jenike.timestep_fraction"),
    ("mpi-ranks", "engine:\n  mpi_ranks: 1000000\n", "engine.mpi_ranks"),
    ("not-finite", "silo_flat:\n  width: .nan\n", "silo_flat.width"),
    ("number-as-text", "materials:\n  hdpe: {youngs_modulus: 5.0e6, poisson_ratio: 0.4, density: 950.0}\n",
     "materials.hdpe.youngs_modulus"),
    ("stiffer-than-anything", "materials:\n  hdpe: {youngs_modulus: 1.0e+300, poisson_ratio: 0.4, density: 950.0}\n",
     "materials.hdpe.youngs_modulus"),
    ("denser-than-anything", "materials:\n  hdpe: {youngs_modulus: 5.0e+6, poisson_ratio: 0.4, density: 1.0e+300}\n",
     "materials.hdpe.density"),
    # names: matched whole, bounded, never a line of a deck
    ("name-trailing-newline", 'silo_flat:\n  particle_model: "sphere2\\n"\n', "silo_flat.particle_model"),
    ("name-deck-injection", 'materials:\n  "hdpe\\nvariable x equal 1": {youngs_modulus: 5.0e+6, poisson_ratio: 0.4}\n',
     "materials"),
    # (YAML takes a key of at most 1024 characters on one line; a longer one is refused as YAML)
    ("name-too-long", f"materials:\n  {'m' * 1000}: {{youngs_modulus: 5.0e+6, poisson_ratio: 0.4}}\n", "materials"),
    ("engine-kind-injection", 'engine:\n  kind: "liggghts; rm -rf ~"\n', "engine.kind"),
    ("executable-shell", 'engine:\n  liggghts:\n    executable: "liggghts; rm -rf ~"\n',
     "engine.liggghts.executable"),
    # keys nothing reads
    ("key-nothing-reads", "silo_recirculation:\n  lti:\n    input_csv: feed.csv\n",
     "silo_recirculation.lti.input_csv"),
    ("typo", "silo_flat:\n  widht: 0.2\n", "did you mean 'silo_flat.width'"),
    ("typo-top-level", "engnie:\n  kind: yade\n", "did you mean 'engine'"),
    ("renamed-key", "engine:\n  executable: liggghts\n", "engine.liggghts.executable"),
    # programs and files the configuration names, checked before the first run
    ("missing-executable", "engine:\n  liggghts:\n    executable: /nonexistent/liggghts\n",
     "config key 'engine.liggghts.executable'"),
    ("missing-mpirun", "engine:\n  mpi_ranks: 2\n  mpirun: /nonexistent/mpirun\n", "config key 'engine.mpirun'"),
    ("missing-yade-python", "engine:\n  yade:\n    python: /nonexistent/python3\nsilo_flat:\n  engine: yade\n",
     "config key 'engine.yade.python'"),
    ("piv-glob-matches-a-folder", "silo_flat:\n  piv:\n    measured:\n      files: ['{tmp}/piv*']\n"
                                  "      units: metres\n      field_interval: 0.01\n      pixel_size: 1.0e-4\n",
     "silo_flat.piv.measured.files"),
    ("piv-file-not-piv", "silo_flat:\n  piv:\n    measured:\n      files: ['{secret}']\n"
                         "      units: metres\n      field_interval: 0.01\n      pixel_size: 1.0e-4\n",
     "secret.txt"),
    ("piv-file-missing", "silo_flat:\n  piv:\n    measured:\n      files: ['{tmp}/none.txt']\n"
                         "      units: metres\n      field_interval: 0.01\n      pixel_size: 1.0e-4\n",
     "silo_flat.piv.measured.files"),
    ("measured-profiles-missing", "silo_flat:\n  fields:\n    measured_profiles: '{tmp}/none.csv'\n",
     "config key 'silo_flat.fields.measured_profiles'"),
    ("measured-profiles-folder", "silo_flat:\n  fields:\n    measured_profiles: '{tmp}/pivdir'\n",
     "config key 'silo_flat.fields.measured_profiles'"),
    ("measured-profiles-not-profiles", "silo_flat:\n  fields:\n    measured_profiles: '{secret}'\n",
     "config key 'silo_flat.fields.measured_profiles'"),
    ("existing-run-missing-folder", "silo_flat:\n  existing_runs:\n    mine:\n      folder: '{tmp}/none'\n"
                                    "      dumps: 'silo*.vtk'\n      width: 0.02\n      depth: 0.02\n"
                                    "      outlet_width: 0.006\n      timestep: 1.0e-5\n      open_time: 0.1\n",
     "silo_flat.existing_runs.mine"),
]


def _workflow_checks(config: dict, config_files: list) -> list:
    """What ``siloflow/workflow/rules/common.smk`` runs when the workflow is parsed, in its order; the measured PIV files."""
    return check_measured_inputs(preflight(config, config_files).config["silo_flat"])


def _as_snakemake_merges(text: str) -> dict:
    """The configuration Snakemake hands the workflow: the default file with the hostile one laid over it where
    that file reads as YAML at all (one it cannot read leaves the default, which the re-reading then refuses)."""
    default = load_config_file(DEFAULT_CONFIG)
    try:
        override = yaml.safe_load(text)
    except yaml.YAMLError:
        return default
    if not isinstance(override, dict) or "__use_yte__" in override or len(text) > 1_000_000:
        return default
    update_config(default, override)  # Snakemake's own merge of its --configfile files
    return default


@pytest.mark.parametrize("name, text, expected", HOSTILE, ids=[case[0] for case in HOSTILE])
def test_a_hostile_configuration_is_refused_at_once_naming_the_key(tmp_path, monkeypatch, name, text, expected):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "pivdir").mkdir()
    secret = tmp_path / "secret.txt"
    secret.write_text(f"{SECRET}\nroot:x:0:0:root:/root:/bin/bash\n")
    hostile = tmp_path / "hostile.yaml"
    text = text.replace("{tmp}", str(tmp_path)).replace("{secret}", str(secret))
    hostile.write_bytes(text.encode("latin-1" if name == "not-utf8" else "utf-8"))
    config = _as_snakemake_merges(hostile.read_text(encoding="utf-8", errors="replace"))
    before = sorted(path.name for path in tmp_path.iterdir())
    start = time.perf_counter()
    with pytest.raises((PreflightError, MeasuredInputError)) as refused:
        _workflow_checks(config, [DEFAULT_CONFIG, hostile])
    elapsed = time.perf_counter() - start
    message = str(refused.value)
    assert expected in message, message
    assert elapsed < REFUSAL_S, f"{name}: refused after {elapsed:.2f} s"
    assert SECRET not in message and "root:x" not in message, message
    # nothing made: no results folder, no run directory, no file beside the configuration
    assert sorted(path.name for path in tmp_path.iterdir()) == before


def test_there_are_at_least_thirty_hostile_configurations_and_the_default_passes(tmp_path, monkeypatch):
    assert len(HOSTILE) >= 30 and len({case[0] for case in HOSTILE}) == len(HOSTILE)
    monkeypatch.chdir(tmp_path)
    accepted = preflight(load_config_file(DEFAULT_CONFIG), [DEFAULT_CONFIG])
    assert set(accepted.cases) == {"jenike", "silo_flat", "silo_recirculation", "blender"}
    assert _workflow_checks(load_config_file(DEFAULT_CONFIG), [DEFAULT_CONFIG]) == [] and accepted.existing_dumps == {}
    assert len(accepted.estimates) == sum(len(runs) for runs in accepted.cases.values())
    assert not any(Path(tmp_path).iterdir())
