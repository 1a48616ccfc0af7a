"""Reader of the products a validation group's rows are computed from, and the digest of the code that computes
them.

The same reader serves the workflow's rows step (the products in the working directory) and the re-derivation of a
recorded group's rows from the products its record keeps (``docs/validation/<group>/products/``), so that a change
of the row code needs no new simulation. The rows themselves are
:func:`siloflow.analysis.studies.validation.group_rows.group_rows`.
"""

from __future__ import annotations

import hashlib
import importlib.util
import json
import os
from collections.abc import Mapping, Sequence
from pathlib import Path

import yaml

from siloflow.analysis.io.tables import read_table
from siloflow.analysis.studies.validation.group_rows import ROW_CODE
from siloflow.model.cases.jenike_sweep import CONFIGURED_POUR

__all__ = ["read_group_products", "row_code_digest"]


def _json(path) -> dict:
    return json.loads(Path(path).read_text(encoding="utf-8"))


def read_group_products(kind: str, inputs: Mapping[str, Sequence[str | os.PathLike]]) -> dict:
    """A group's products as its rows take them.

    Parameters
    ----------
    kind : str
        The group's case kind.
    inputs : mapping
        ``{name: [file]}`` as the rows step names them: for ``jenike`` ``summaries`` (each run's
        ``metrics/bulk_friction.json``) and, for the calibration group, ``parameters`` (one ``parameters.yaml``);
        for ``silo_flat`` one list per key of :data:`siloflow.engines.layout.SILO_ROW_PRODUCTS`, run by run; for
        ``silo_recirculation`` ``cases``, ``summaries`` and ``rtds``; for ``blender`` ``cases`` and ``summaries``.

    Returns
    -------
    dict
        ``{"summaries": [...], "parameters": ... or None}`` for ``jenike``; ``{"runs": [...]}`` otherwise, one
        mapping per run (``case``, ``summary``, ``rtd``, or the silo's ``case``, ``flow``, ``fields``, ``balance``,
        ``janssen``, ``kinematic``, ``boundary``).
    """
    if kind == "jenike":
        parameters = list(inputs.get("parameters") or [])
        # a shear test recorded before the pour variant existed has no "pour": its sample was poured as configured
        return {"summaries": [{"pour": CONFIGURED_POUR, **_json(path)} for path in inputs["summaries"]],
                "parameters": yaml.safe_load(Path(parameters[0]).read_text(encoding="utf-8")) if parameters else None}
    if kind == "silo_flat":
        runs = []
        for paths in zip(*(inputs[key] for key in ("case", "flow", "fields", "balance", "janssen", "kinematic",
                                                   "boundary"))):
            case, flow, fields, balance, janssen, kinematic, boundary = paths
            runs.append({"case": _json(case), "flow": _json(flow), "fields": _json(fields), "balance": _json(balance),
                         "janssen": read_table(janssen), "kinematic": read_table(kinematic),
                         "boundary": read_table(boundary)})
        return {"runs": runs}
    if kind == "silo_recirculation":
        return {"runs": [{"case": _json(case), "summary": _json(summary), "rtd": read_table(rtd)}
                         for case, summary, rtd in zip(inputs["cases"], inputs["summaries"], inputs["rtds"])]}
    if kind == "blender":
        return {"runs": [{"case": _json(case), "summary": _json(summary)}
                         for case, summary in zip(inputs["cases"], inputs["summaries"])]}
    raise ValueError(f"no validation products for case kind {kind!r}")


def row_code_digest(modules: Sequence[str] = ROW_CODE) -> str:
    """SHA-256 (hex, first 16 digits) of the source files of the modules that decide a group's rows
    (:data:`~siloflow.analysis.studies.validation.group_rows.ROW_CODE`), in order: a record whose digest differs was
    written by other row code."""
    digest = hashlib.sha256()
    for name in modules:
        spec = importlib.util.find_spec(name)
        if spec is None or spec.origin is None:
            raise ValueError(f"no source for module {name!r}")
        digest.update(name.encode())
        digest.update(Path(spec.origin).read_bytes())
    return digest.hexdigest()[:16]
