"""Reader and writer of the validation record's files (``docs/validation/<group>/``): ``table.csv``, ``runs.csv``, the
group's plots and, for a group whose runs another group reads, those runs' products (``products/``). The record itself
(its columns, its page) is :mod:`siloflow.analysis.studies.validation.record`.

The record keeps PNG plots (:data:`RECORD_PLOT_FORMAT`): small, and shown on its page. A workflow whose
``plots.format`` is ``pdf`` or ``svg`` cannot make it: the record refuses such plots (:func:`check_plot_format`,
before anything runs where the workflow asks for a record) rather than converting them, which would need a PDF or
SVG renderer. The validation scale's configuration, config/validation.yaml, keeps the default format, png.
A plot enters the record as a 256-colour PNG (:func:`write_record_plot`): a third of matplotlib's full-colour file,
which keeps the whole record, plots included, well under 2 MB.
"""

from __future__ import annotations

import csv
import json
import os
import shutil
import time
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path

from PIL import Image

from siloflow.model.checks import number_or_nan
from siloflow.analysis.io.tables import write_flow_table, write_json
from siloflow.analysis.studies.validation.hypothesis import HYPOTHESIS_COLUMNS, HYPOTHESIS_NUMBERS
from siloflow.analysis.studies.validation.record import RUN_COLUMNS, GroupRecord
from siloflow.analysis.studies.validation.rows import COLUMNS, NO_FINDING

__all__ = ["TABLE", "RUNS", "DERIVATION", "PRODUCTS", "RECORD_PLOT_FORMAT", "RECORD_PLOT_COLOURS", "check_plot_format", "benchmark_wall_time",
           "read_validation_rows", "write_record_plot", "write_group_record", "read_group_record", "read_record", "restore_products",
           "HYPOTHESES_DIR", "write_hypothesis_record", "read_hypothesis_records"]

#: A group's table rows and its runs' provenance, in its folder.
TABLE, RUNS = "table.csv", "runs.csv"
#: What re-derives a group's rows from the products its record keeps: the case kind, the configuration keys the rows
#: use, the products by name and the digest of the row code that wrote the table.
DERIVATION = "derivation.json"
#: The folder of a group's record that keeps the products of its runs another group reads, each under its path in the
#: workflow's working directory (``products/results/...``).
PRODUCTS = "products"
#: The folder of the record that keeps the measured hypotheses, one ``<name>.csv`` each
#: (:mod:`siloflow.analysis.studies.validation.hypothesis`).
HYPOTHESES_DIR = "hypotheses"
#: The format of a record's plots, their file name suffix (see the module's notes).
RECORD_PLOT_FORMAT = "png"


def check_plot_format(plot_format: str) -> None:
    """Refuse (ValueError) to make a record from plots of ``plot_format`` (the configuration's ``plots.format``, or
    a plot file's suffix without the dot) unless it is :data:`RECORD_PLOT_FORMAT`, saying what to set."""
    if plot_format != RECORD_PLOT_FORMAT:
        raise ValueError(f"the validation record keeps {RECORD_PLOT_FORMAT} plots (small, shown on its page in "
                         f"docs/validation/), not {plot_format or 'files without a suffix'}: make it with plots.format: "
                         f"{RECORD_PLOT_FORMAT} (the default, as config/validation.yaml has it)")


#: Colours of a record plot's palette: a matplotlib plot has few distinct colours besides its antialiased edges.
RECORD_PLOT_COLOURS = 256


def write_record_plot(source: str | os.PathLike, destination: str | os.PathLike) -> Path:
    """Write the PNG plot ``source`` to ``destination`` as a PNG of at most :data:`RECORD_PLOT_COLOURS` colours.

    Median-cut palette without dithering (Pillow), so flat areas and lines stay flat; transparency is dropped onto
    white, the page's background. Returns the destination.
    """
    with Image.open(source) as image:
        # every mode converts to RGBA (opaque where it has no alpha), so one composite covers them all
        rgba = image.convert("RGBA")
        rgb = Image.new("RGB", rgba.size, "white")
        rgb.paste(rgba, mask=rgba.getchannel("A"))
        palette = rgb.quantize(colors=RECORD_PLOT_COLOURS, method=Image.Quantize.MEDIANCUT, dither=Image.Dither.NONE)
        palette.save(destination, format="PNG", optimize=True)
    return Path(destination)


def _product_path(name: str) -> Path:
    """``name`` as a path relative to the working directory, refused (ValueError) if it could leave it."""
    path = Path(name)
    if path.is_absolute() or ".." in path.parts or not path.parts:
        raise ValueError(f"a record product is a path inside the working directory, got {name!r}")
    return path


def write_group_record(directory: str | os.PathLike, rows: Sequence[Mapping], runs: Sequence[Mapping],
                       plots: Mapping[str, str | os.PathLike],
                       products: Mapping[str, str | os.PathLike] | None = None,
                       derivation: Mapping | None = None) -> Path:
    """Write one group's record into ``directory``: its rows, its runs, its plots (``{name: source file}``), the
    products its rows are computed from and those of its runs another group reads (``{path in the working directory:
    source file}``, under :data:`PRODUCTS`) and what re-derives its rows (:data:`DERIVATION`, when given), replacing
    the group's previous record there (a plot or product no longer made is removed). Returns the folder."""
    directory = Path(directory)
    if not rows or not runs:
        raise ValueError(f"a group's record needs rows and runs; got {len(rows)} rows and {len(runs)} runs")
    products = {_product_path(name): Path(source) for name, source in (products or {}).items()}
    for name, source in plots.items():
        if Path(name).name != name or Path(name).suffix != f".{RECORD_PLOT_FORMAT}":
            raise ValueError(f"a record plot is a {RECORD_PLOT_FORMAT.upper()} file name without a folder, got {name!r}")
        check_plot_format(Path(source).suffix.lstrip("."))
    directory.mkdir(parents=True, exist_ok=True)
    write_flow_table(directory / TABLE, [{column: row[column] for column in COLUMNS} for row in rows])
    # a record written before a provenance column existed leaves it empty
    write_flow_table(directory / RUNS, [{column: run.get(column, "") for column in RUN_COLUMNS} for run in runs])
    if derivation is not None:
        write_json(directory / DERIVATION, derivation)
    for stale in directory.glob(f"*.{RECORD_PLOT_FORMAT}"):
        if stale.name not in plots:
            stale.unlink()
    for name, source in plots.items():
        write_record_plot(source, directory / name)
    kept = directory / PRODUCTS
    # read whole before the folder is replaced: the sources may be the previous record's own products
    contents = {name: source.read_bytes() for name, source in products.items()}
    if kept.is_dir():
        shutil.rmtree(kept)
    for name, content in contents.items():
        (kept / name).parent.mkdir(parents=True, exist_ok=True)
        (kept / name).write_bytes(content)
    return directory


def benchmark_wall_time(path: str | os.PathLike) -> float:
    """Wall time of a job (s) from the tab-separated benchmark Snakemake writes (its column ``s``; the last row when
    the job was repeated)."""
    with open(path, newline="", encoding="utf-8") as handle:
        rows = list(csv.DictReader(handle, delimiter="\t"))
    if not rows or "s" not in rows[-1]:
        raise ValueError(f"{path}: not a Snakemake benchmark (no row with a column s)")
    return float(rows[-1]["s"])


#: The numeric columns of the validation table; the others are text (a study value such as "667" stays as written).
NUMBERS = ("value", "value_error")
#: What a table written by older row code (a single verdict, ``scale_shows``) lacks, as read: no finding, no verdict.
LEGACY_MARK = "written by older row code, before the rows were judged against the study's findings"


def _legacy(row: Mapping) -> dict:
    """A row of a table written before the rows had findings, in today's columns, judged against nothing."""
    return {**{column: "" for column in COLUMNS}, "group": row["group"], "figure": row["figure"], "case": row["case"],
            "finding": NO_FINDING, "value": row["value"], "value_error": row["value_error"], "unit": row["unit"],
            "study": row.get("study_value") or "-", "agreement": NO_FINDING, "scale": NO_FINDING,
            "evidence": f"({LEGACY_MARK}) {row.get('evidence', '')}"}


def read_validation_rows(path: str | os.PathLike) -> list[dict]:
    """Rows of a validation table CSV (:data:`siloflow.analysis.studies.validation.rows.COLUMNS`): value and error as float
    (NaN where empty), every other column as text. A table written by older row code (with ``scale_shows``) is read
    with no finding and no verdict, its evidence marked (:data:`LEGACY_MARK`)."""
    with open(path, newline="", encoding="utf-8") as handle:
        rows = list(csv.DictReader(handle))
    if rows and "scale_shows" in rows[0] and "agreement" not in rows[0]:
        rows = [_legacy(row) for row in rows]
    missing = [column for column in COLUMNS if rows and column not in rows[0]]
    if missing:
        raise ValueError(f"{path}: a validation table needs the columns {', '.join(missing)}")
    return [{column: number_or_nan(row[column] or None) if column in NUMBERS else row[column] for column in COLUMNS}
            for row in rows]


def _runs(path: Path) -> list[dict]:
    # as text: a commit or a seed list must not be read as a number
    with open(path, newline="", encoding="utf-8") as handle:
        rows = list(csv.DictReader(handle))
    if rows and "run_id" not in rows[0]:
        raise ValueError(f"{path}: the provenance has no run_id column")
    return rows


def read_group_record(directory: str | os.PathLike) -> GroupRecord:
    """One group's record from its folder (written by :func:`write_group_record`)."""
    directory = Path(directory)
    rows = read_validation_rows(directory / TABLE) if (directory / TABLE).is_file() else []
    kept = directory / PRODUCTS
    products = sorted(path.relative_to(kept).as_posix() for path in kept.rglob("*") if path.is_file())
    plots = sorted(p.name for p in directory.glob(f"*.{RECORD_PLOT_FORMAT}"))
    derivation = (json.loads((directory / DERIVATION).read_text(encoding="utf-8"))
                  if (directory / DERIVATION).is_file() else None)
    return GroupRecord(rows=rows, runs=_runs(directory / RUNS), plots=plots, products=products, derivation=derivation)


def read_record(record_dir: str | os.PathLike, groups: Iterable[str]) -> dict[str, GroupRecord]:
    """``{group: GroupRecord}`` of the groups with a record (a ``runs.csv``) under ``record_dir``."""
    return {name: read_group_record(Path(record_dir) / name) for name in groups
            if (Path(record_dir) / name / RUNS).is_file()}


def restore_products(directory: str | os.PathLike, workdir: str | os.PathLike) -> list[Path]:
    """Copy the products a group's record keeps (its folder ``directory``) into the working directory ``workdir``
    where they are missing, so that the workflow reads them instead of making their runs again; a file already
    there is left as it is. Returns the files copied.

    Every file copied gets one modification time: a run's record copied after its metrics would otherwise look newer
    than them, and Snakemake would make the metrics again, and the run before them."""
    directory, workdir = Path(directory), Path(workdir)
    copied = []
    for name in read_group_record(directory).products:
        target = workdir / _product_path(name)
        if not target.exists():
            target.parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(directory / PRODUCTS / name, target)
            copied.append(target)
    stamp = time.time()
    for target in copied:
        os.utime(target, (stamp, stamp))
    return copied


def write_hypothesis_record(path: str | os.PathLike, rows: Sequence[Mapping]) -> Path:
    """Write a measured hypothesis's record (:data:`HYPOTHESIS_COLUMNS`, one row per compared row), atomically."""
    missing = [column for column in HYPOTHESIS_COLUMNS if rows and column not in rows[0]]
    if not rows or missing:
        raise ValueError(f"{path}: a hypothesis's record needs at least one row with the columns "
                         f"{', '.join(missing or HYPOTHESIS_COLUMNS)}")
    return write_flow_table(path, [{column: row[column] for column in HYPOTHESIS_COLUMNS} for row in rows])


def read_hypothesis_records(record_dir: str | os.PathLike) -> list[dict]:
    """Every measured hypothesis's rows under ``record_dir`` (:data:`HYPOTHESES_DIR`), the hypotheses in name order;
    numbers as float (NaN where empty), the other columns as text. None recorded: an empty list."""
    rows = []
    for path in sorted((Path(record_dir) / HYPOTHESES_DIR).glob("*.csv")):
        with open(path, newline="", encoding="utf-8") as handle:
            read = list(csv.DictReader(handle))
        missing = [column for column in HYPOTHESIS_COLUMNS if read and column not in read[0]]
        if missing:
            raise ValueError(f"{path}: a hypothesis's record needs the columns {', '.join(missing)}")
        rows += [{column: number_or_nan(row[column] or None) if column in HYPOTHESIS_NUMBERS else row[column]
                  for column in HYPOTHESIS_COLUMNS} for row in read]
    return rows
