"""The `siloflow` command: every command answers --help, and a missing file, a misspelt key or a bad option is
answered in one line on standard error with exit code 2, never a traceback, before anything runs."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from siloflow.cli.main import main
from siloflow.engines.config import load_config
from siloflow.engines.planning import config_estimates
from tests.repo import REPO_ROOT

#: Every command and verb, with the options it needs besides --config.
COMMANDS = {
    ("run",): [],
    ("check",): [],
    ("estimate",): [],
    ("render",): ["--output", "{tmp}/inputs"],
    ("status",): ["--directory", "{tmp}"],
    ("record", "status"): [],
    ("record", "publish"): ["--directory", "{tmp}"],
    ("record", "page"): ["--record", "{tmp}"],
    ("record", "check"): ["--group", "silo"],
    ("record", "restore"): ["--group", "silo", "--directory", "{tmp}"],
    ("record", "finished"): ["--directory", "{tmp}"],
}
#: The commands that read a configuration (``record publish`` copies a record and reads none).
READS_CONFIG = [command for command in COMMANDS if command != ("record", "publish")]
CONSOLE_SCRIPT = Path(sys.executable).with_name("siloflow")


def _words(command: tuple[str, ...], tmp_path: Path) -> list[str]:
    return [*command, *(word.format(tmp=tmp_path) for word in COMMANDS[command])]


def _one_line_refusal(capsys, code: int) -> str:
    captured = capsys.readouterr()
    assert code == 2
    lines = captured.err.splitlines()
    assert len(lines) == 1, captured.err
    assert "Traceback" not in captured.err
    return lines[0]


@pytest.mark.parametrize("command", [(), *COMMANDS], ids=lambda command: " ".join(command) or "siloflow")
def test_every_command_answers_help(command, capsys):
    assert main([*command, "--help"]) == 0
    out = capsys.readouterr().out
    assert out.startswith(f"usage: siloflow {' '.join(command)}".rstrip())
    if command and command != ("record",):
        assert "--config FILE" in out and "--cores N" in out


@pytest.mark.parametrize("command", READS_CONFIG, ids=" ".join)
def test_a_missing_config_file_is_one_line_and_exit_code_2(command, tmp_path, capsys):
    missing = tmp_path / "no-such.yaml"
    line = _one_line_refusal(capsys, main([*_words(command, tmp_path), "--config", str(missing)]))
    assert line == f"siloflow {command[0]}: config file {str(missing)!r}: no such file"


@pytest.mark.parametrize("command", READS_CONFIG, ids=" ".join)
def test_a_misspelt_key_is_one_line_naming_it_and_exit_code_2(command, tmp_path, capsys):
    config = tmp_path / "misspelt.yaml"
    config.write_text("silo_flat:\n  sed: 3\n")
    line = _one_line_refusal(capsys, main([*_words(command, tmp_path), "--config", str(config)]))
    assert line.startswith(f"siloflow {command[0]}: ")
    assert "'silo_flat.sed' is not a siloflow setting: did you mean 'silo_flat.seed'?" in line
    assert not (tmp_path / "inputs").exists() and not (tmp_path / ".snakemake").exists()


@pytest.mark.parametrize("command", list(COMMANDS), ids=" ".join)
def test_a_misspelt_option_is_one_line_and_exit_code_2(command, tmp_path, capsys):
    line = _one_line_refusal(capsys, main([*_words(command, tmp_path), "--corse", "4"]))
    assert "unrecognized arguments: --corse 4" in line and line.endswith("--help)")


def test_cores_takes_a_whole_number_of_at_least_one(capsys):
    line = _one_line_refusal(capsys, main(["check", "--cores", "0"]))
    assert line == ("siloflow check: error: argument --cores: takes a whole number of cores >= 1, got '0' "
                    "(see siloflow check --help)")


def test_no_command_prints_the_usage_and_exit_code_2(capsys):
    assert main([]) == 2
    assert capsys.readouterr().err.startswith("usage: siloflow")


def test_check_validates_and_plans_the_default_configuration_running_nothing(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(REPO_ROOT)
    assert main(["check"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("config/config.yaml: valid. 17 engine runs (jenike 12, silo_flat 1, silo_recirculation 2, "
                          "blender 2)")
    assert "Nothing was run" in out


def test_render_writes_each_runs_inputs_and_never_into_a_folder_that_holds_something(tmp_path, capsys):
    output = tmp_path / "inputs"
    assert main(["render", "--config", str(REPO_ROOT / "config" / "config.yaml"), "--output", str(output)]) == 0
    decks = sorted(path.parent.parent.relative_to(output).parts[0] for path in output.glob("*/*/deck/case.json"))
    assert decks == ["blender"] * 2 + ["jenike"] * 12 + ["silo_flat"] + ["silo_recirculation"] * 2
    assert "17 runs' engine inputs written" in capsys.readouterr().out
    before = sorted(output.rglob("*"))
    line = _one_line_refusal(capsys, main(["render", "--config", str(REPO_ROOT / "config" / "config.yaml"),
                                           "--output", str(output)]))
    assert "exists and is not an empty folder" in line and sorted(output.rglob("*")) == before


def test_status_reads_a_finished_an_unfinished_and_a_foreign_run_off_the_disk(tmp_path, capsys):
    config = str(REPO_ROOT / "config" / "config.yaml")
    assert main(["status", "--config", config, "--directory", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "in all: 0 finished, 0 unfinished, 17 to do" in out and "report: none yet" in out
    (first, second), root = sorted(main_runs(config, "blender")), tmp_path / "results" / "blender"
    (root / first / "deck").mkdir(parents=True)
    (root / first / "run.json").write_text("{}")
    (root / second / "deck").mkdir(parents=True)
    (root / "diverging-g1-0000000000" / "deck").mkdir(parents=True)
    (tmp_path / "results" / "report.html").write_text("")
    assert main(["status", "--config", config, "--directory", str(tmp_path)]) == 0
    out = capsys.readouterr().out.splitlines()
    assert "blender: 1 finished, 1 unfinished" in out and f"  unfinished (the next run resumes it): {second}" in out
    assert any(line.startswith("blender: 1 folder(s) this configuration does not plan") and
               line.endswith(": diverging-g1-0000000000") for line in out)
    assert "in all: 1 finished, 1 unfinished, 15 to do, under " + str(tmp_path / "results") + "/" in out


def main_runs(config: str, kind: str) -> list[str]:
    return [estimate.run_id for estimate in config_estimates(load_config(config)) if estimate.kind == kind]


@pytest.mark.parametrize("entry", [[str(CONSOLE_SCRIPT)], [sys.executable, "-m", "siloflow"]],
                         ids=["console script", "python -m siloflow"])
def test_the_installed_entry_points_answer_help_and_refuse_in_one_line(entry, tmp_path):
    helped = subprocess.run([*entry, "--help"], capture_output=True, text=True, check=False)
    assert helped.returncode == 0 and helped.stdout.startswith("usage: siloflow")
    refused = subprocess.run([*entry, "check", "--config", str(tmp_path / "none.yaml")], capture_output=True,
                             text=True, check=False)
    assert refused.returncode == 2 and refused.stderr.count("\n") == 1 and "no such file" in refused.stderr
