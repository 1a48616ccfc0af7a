"""The documentation: the MkDocs site builds with --strict (a broken link, a missing page or an API docstring the
renderer cannot read fails it) and has every page of its navigation, the README stays a short entry point, and every
module, rule and config key the manual names exists, so that the manual cannot go stale silently.
`make docs` runs the same build; this test runs it on every `make test`."""

from __future__ import annotations

import dataclasses
import functools
import importlib
import importlib.util
import os
import re
import subprocess
import sys
from pathlib import Path, PurePosixPath

import pytest
import yaml

from siloflow.engines.config import RENAMED_KEYS, REPLACED_KEYS, load_schema
from tests.repo import REPO_ROOT
from siloflow.engines.validation_groups import group_of_part

README_MAX_LINES = 220


def _nav_pages(entries) -> list[str]:
    """Every Markdown page the navigation names, in order (entries are 'page.md', {title: 'page.md'} or
    {title: [entries]})."""
    pages = []
    for entry in entries:
        values = entry.values() if isinstance(entry, dict) else [entry]
        for value in values:
            pages.extend(_nav_pages(value) if isinstance(value, list) else [value])
    return pages


def _built_page(page: str) -> PurePosixPath:
    """Where the site puts a page with ``use_directory_urls: false``: ``a/b.md`` is ``a/b.html``, and a folder's
    ``index.md`` or ``README.md`` is its ``index.html``."""
    path = PurePosixPath(page)
    name = "index" if path.stem in ("index", "README") else path.stem
    return path.with_name(f"{name}.html")


def test_the_navigation_names_pages_that_exist():
    config = yaml.safe_load((REPO_ROOT / "mkdocs.yml").read_text(encoding="utf-8"))
    pages = _nav_pages(config["nav"])
    assert pages, "mkdocs.yml has no navigation"
    missing = [page for page in pages if not (REPO_ROOT / "docs" / page).is_file()]
    assert not missing, f"mkdocs.yml names pages that are not in docs/: {missing}"
    assert "validation/README.md" in pages, "the validation record is a page of the site"


@pytest.mark.skipif(importlib.util.find_spec("mkdocs") is None,
                    reason="mkdocs is not installed (the docs extra: pip install -e '.[docs]', which make install does)")
def test_the_site_builds_strictly_with_every_page_of_its_navigation(tmp_path):
    site = tmp_path / "site"
    result = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(site)],
                            cwd=REPO_ROOT, capture_output=True, text=True, timeout=300,
                            env={**os.environ, "NO_MKDOCS_2_WARNING": "1"})
    assert result.returncode == 0, f"mkdocs build --strict failed:\n{result.stdout}\n{result.stderr}"
    config = yaml.safe_load((REPO_ROOT / "mkdocs.yml").read_text(encoding="utf-8"))
    unbuilt = [page for page in _nav_pages(config["nav"]) if not (site / _built_page(page)).is_file()]
    assert not unbuilt, f"pages of the navigation the build did not write: {unbuilt}"
    # the validation record's links point at the files beside it, which the site must carry
    assert (site / "validation" / "silo" / "runs.csv").is_file()
    # the API reference is rendered from the docstrings, not left as its ::: directives
    api = (site / "api" / "engines.html").read_text(encoding="utf-8")
    assert "siloflow.engines.interface" in api and ":::" not in api


def test_the_readme_is_a_short_entry_point_with_the_two_commands():
    lines = (REPO_ROOT / "README.md").read_text(encoding="utf-8").splitlines()
    assert len(lines) <= README_MAX_LINES, f"README.md has {len(lines)} lines; the manual belongs in docs/"
    text = "\n".join(lines)
    assert "make run" in text and "make test" in text


# --- Every name the manual gives exists ------------------------------------------------------------------------------
# The pages are read as text: their inline code spans (`...`), their fenced code blocks and the API pages' `::: module`
# lines. What a span names is told by its form, and only those forms are checked:
#   path        a path into the repository (`siloflow/engines/preflight.py`, `siloflow/templates/liggghts/`; in a fenced folder listing
#               also relative to the folder its line describes); <placeholders>, * globs and ... are left alone
#   source      a bare source file name (`case_deck.py`, `macros.j2`): a file of that name in the repository, in the
#               folder when the prose lists it after one ("`siloflow/analysis/studies/blender/`: `modes.py`, `study.py`")
#   python      a dotted name in the project's packages (`siloflow.engines.preflight.preflight`), `python -m <module>`,
#               `::: <module>`, or a name given from a module's last part (`physics.free_fall_time`)
#   key         a config key: a dotted name whose first part is a top-level section of the schema, one given relative
#               to its section (`fill.balance_planes`), a setting (`davis.out_of_plane: keep`), a key in a formula
#               (`Nr = tracer.start_recirculations`), and the keys of a fenced YAML example; `[]` stands for a
#               list's items (`contacts[].restitution`, as docs/configuration-reference.md writes them)
#   rule        a Snakemake rule: a span the prose calls a rule ("rule `silo_piv_compare`") or `snakemake <target>`
#   make        `make <target>`
#   variable    a variable a command sets (`make estimate CONFIG=...`, `SILOFLOW_UPDATE_GOLDEN=1 python ...`): the
#               Makefile or the Python source reads it
#   group       a validation group or part (`make validate GROUP=silo_2`)
#   identifier  a class of the project (`PlanarField.kind`, `RunRecord`) or a module-level constant (`CASE_KINDS`)
#   function    a called name (`engine_named(record.engine)`, `stages()`): a function or method of the project
#   defined     a name the prose places in a file ("`stable_timestep` in `siloflow/model/cases/physics.py`")
# Anything else (engine commands, math, output columns and files, values, results/ paths) is prose and is not
# checked. A dotted name that may be either a module or a config key (`calibration.shape`, `shear.velocity`) passes
# as either.

#: The pages checked: the README and the manual, not the validation record (docs/validation/README.md and its
#: groups' folders), which the pipeline writes.
DOC_GLOBS = ("README.md", "docs/**/*.md")
GENERATED_DOCS = ("docs/validation/README.md", "docs/validation/*/**/*.md")

#: The project's Python packages: a dotted name starting with one of them is imported.
PACKAGES = ("model", "engines", "analysis", "calibration", "siloflow")
#: A span that starts with one of these (or is one of the root files) is a path into the repository.
PATH_ROOTS = (*PACKAGES, "workflow", "templates", "tests", "config", "docs", "profiles", "examples")
ROOT_FILES = ("Makefile", "Snakefile", "pyproject.toml", "mkdocs.yml")
#: Bare file names of these kinds (`case_deck.py`, `macros.j2`) name a file somewhere in the repository.
SOURCE_SUFFIXES = ("py", "smk", "j2")
#: A dotted span whose last part is one of these is a file name (`fields.json`, `profiles.csv`), not a key.
FILE_SUFFIXES = frozenset("json csv png py npz vti vtk pvd yaml yml md html txt tsv log smk j2 stl h liggghts".split())

#: Names the manual gives on purpose although nothing defines them, each with why. The test checks that each is still
#: in the manual and still undefined, so that this list cannot go stale either. (Keys of earlier versions that the
#: manual names as such need no entry: siloflow.engines.config's RENAMED_KEYS and REPLACED_KEYS list them.)
DELIBERATELY_UNDEFINED = {
    "silo_flat.widht": "configuration.md's example of a misspelt key, which the preflight refuses with 'did you mean'",
}

_PATH_TOKEN = re.compile(r"(?<![\w./<>*~$-])((?:%s)/[^\s,;:()'\"`]*|(?:%s)(?![\w.-]))"
                         % ("|".join(PATH_ROOTS), "|".join(re.escape(name) for name in ROOT_FILES)))
_SOURCE_TOKEN = re.compile(r"(?<![\w./<>*~$-])(\w[\w.]*\.(?:%s))(?![\w.])" % "|".join(SOURCE_SUFFIXES))
_PLACEHOLDER = re.compile(r"<[^<>]*>|\*")
_DOTTED = re.compile(r"(?:[A-Za-z_]\w*|<[\w-]+>)(?:\.(?:\w+|<[\w-]+>|\*))+")
_IDENTIFIER = re.compile(r"[a-z][a-z0-9_]*")
_SETTING = re.compile(r"([A-Za-z_][\w.]*): (.+)")
_CAMEL = re.compile(r"([A-Z][a-z0-9]+(?:[A-Z][a-z0-9]*)*)(?:\.(\w+))?")
_CONSTANT = re.compile(r"[A-Z][A-Z0-9]*(?:_[A-Z0-9]+)+")
_INLINE_CODE = re.compile(r"(?<!`)(`+)(?!`)(.+?)(?<!`)\1(?!`)", re.S)
_FENCE = re.compile(r"\s*(`{3,}|~{3,})\s*([\w+-]*)")
_MAKE = re.compile(r"(?:^|[;&|]\s*|\btime\s+)make\s+([\w-]+)((?:\s+[A-Z_]+=\S*)*)")
_VARIABLE = re.compile(r"(?:^|\s)([A-Z][A-Z0-9_]*)=(\S*)")
_SNAKEMAKE = re.compile(r"(?:^|[;&|]\s*)snakemake\s+([^\s;&|]+)")
_PYTHON_M = re.compile(r"\bpython3?\s+-m\s+([\w.]+)")
# a span the sentence calls a rule: "rule `a`", "rules `a`, `b` and `c`", "the `a` rule"
_RULE_BEFORE = re.compile(r"\brules?\s+(?:`[^`]*`\s*(?:,|\band\b|\bor\b)\s*)*$", re.I)
_RULE_AFTER = re.compile(r"\s+rules?\b", re.I)
# "`name` in `path`": the name is defined in that file
_DEFINED_IN = re.compile(r"\s+in\s+`([^`]+)`")
# "`folder/`: `a.py`, `b.py`": the files are in that folder
_LISTED_IN = re.compile(r"`([^`]+/)`\s*:\s*(?:`[^`]+`\s*,\s*)*$")
_CALL = re.compile(r"([a-z_][a-z0-9_]*)\(.*\)")
_KEY_TOKEN = re.compile(r"(?<![\w./<>-])[a-z_]\w*(?:\.\w+)+(?![\w(/.-])")


@dataclasses.dataclass(frozen=True)
class DocName:
    """A name the manual gives: its kind (one of the kinds above, or two joined by | when it may be either), the name
    and where ('docs/page.md:line')."""

    kind: str
    name: str
    where: str


def _doc_pages() -> list[Path]:
    pages = {path for pattern in DOC_GLOBS for path in REPO_ROOT.glob(pattern)}
    generated = {path for pattern in GENERATED_DOCS for path in REPO_ROOT.glob(pattern)}
    return sorted(pages - generated)


def _split_fences(text: str) -> tuple[list[str], list[tuple[int, str, list[str]]]]:
    """The page's prose lines (every line of a fenced block blanked, so that line numbers keep) and its fenced blocks
    as (number of their first line inside, language, lines)."""
    prose, blocks, fence = [], [], None
    for number, line in enumerate(text.splitlines(), 1):
        if fence is None:
            if (match := _FENCE.match(line)):
                fence = (match.group(1), match.group(2).lower(), number + 1, [])
            prose.append("" if match else line)
            continue
        closing = line.strip()
        if closing and set(closing) == {fence[0][0]} and len(closing) >= len(fence[0]):
            blocks.append((fence[2], fence[1], fence[3]))
            fence = None
        else:
            fence[3].append(line)
        prose.append("")
    return prose, blocks


def _inline_spans(prose: list[str]):
    """Every inline code span of the prose as (line number, code, the paragraph's text before it, the paragraph's
    text after it)."""
    paragraph: list[str] = []
    for number, line in enumerate([*prose, ""], 1):
        if line.strip():
            paragraph.append(line)
            continue
        if paragraph:
            text, first = "\n".join(paragraph), number - len(paragraph)
            for match in _INLINE_CODE.finditer(text):
                code = match.group(2).replace("\n", " ")
                if code.startswith(" ") and code.endswith(" ") and code.strip():
                    code = code[1:-1]
                before, after = text[:match.start()].replace("\n", " "), text[match.end():].replace("\n", " ")
                yield first + text.count("\n", 0, match.start()), code, before, after
        paragraph = []


def _mapping_keys(value) -> list[str]:
    """Every key path of a YAML value, through mappings and the mappings in lists."""
    if isinstance(value, list):
        return [key for item in value for key in _mapping_keys(item)]
    if not isinstance(value, dict):
        return []
    return [path for key, item in value.items()
            for path in (str(key), *(f"{key}.{inner}" for inner in _mapping_keys(item)))]


def _setting_keys(code: str) -> list[str]:
    """The keys a `key: value` span sets (`davis.out_of_plane: keep`, `verification: {enabled: false}`)."""
    match = _SETTING.fullmatch(code)
    if not match:
        return []
    try:
        value = yaml.safe_load(match.group(2))
    except yaml.YAMLError:
        value = None
    return [match.group(1), *(f"{match.group(1)}.{key}" for key in _mapping_keys(value))]


def _dotted_kind(name: str) -> str | None:
    """What a dotted name may be (python, key, or both as 'python|key'); None: nothing of the project's."""
    first = name.split(".")[0]
    sections = _schema()["properties"]
    if first in PACKAGES:  # `calibration` is a package and a section
        return "python|key" if first in sections else "python"
    if first in sections or _PLACEHOLDER.fullmatch(first):
        return "key"  # a section's key, not a module of the same last name (`engine.kind`, `blender.inserts`)
    kinds = [kind for kind, known in (("python", _project_modules()), ("key", _nested_key_nodes())) if first in known]
    return "|".join(kinds) or None


def _file_names(code: str, where: str, folder: str = "") -> list[DocName]:
    """Repository paths and bare source file names in a span or a line of a fenced block; ``folder`` is the folder
    a folder listing's line describes, against which a path that is not the repository's may be read."""
    names = []
    for token in _PATH_TOKEN.findall(code):
        token = token.rstrip(".")
        if _PLACEHOLDER.search(token) or "..." in token or "{" in token:
            continue
        if folder and token != folder and not (REPO_ROOT / token).exists() and (REPO_ROOT / folder / token).exists():
            token = folder + token
        names.append(DocName("path", token, where))
    return names + [DocName("source", token, where) for token in _SOURCE_TOKEN.findall(code)]


def _command_names(code: str, where: str) -> list[DocName]:
    """The make targets and variables, validation groups, Snakemake targets, modules run by `python -m` and
    environment variables of a command line."""
    names = []
    for target, variables in _MAKE.findall(code):
        names.append(DocName("make", target, where))
        names += [DocName("group", value, where) for variable, value in _VARIABLE.findall(variables)
                  if variable == "GROUP" and not _PLACEHOLDER.search(value)]
    names += [DocName("variable", variable, where) for variable, _ in _VARIABLE.findall(code)]
    names += [DocName("rule", target, where) for target in _SNAKEMAKE.findall(code) if _IDENTIFIER.fullmatch(target)]
    names += [DocName("python", module, where) for module in _PYTHON_M.findall(code)
              if module.split(".")[0] in PACKAGES]
    return names


def _span_names(code: str, before: str, after: str, where: str) -> list[DocName]:
    """What one inline code span names."""
    names = _file_names(code, where) + _command_names(code, where)
    word = re.fullmatch(r"\w+", code) is not None
    if (match := re.fullmatch(r"rules? (\w+)", code)):
        names.append(DocName("rule", match.group(1), where))
    elif _IDENTIFIER.fullmatch(code) and (_RULE_BEFORE.search(before) or _RULE_AFTER.match(after)):
        names.append(DocName("rule", code, where))
    elif word and (match := _DEFINED_IN.match(after)) and _PATH_TOKEN.fullmatch(match.group(1)):
        names.append(DocName("defined", f"{code} in {match.group(1)}", where))
    elif (sources := [name for name in names if name.kind == "source"]) and (match := _LISTED_IN.search(before)):
        listed = [DocName("path", match.group(1) + name.name, where) for name in sources]
        names = [*(name for name in names if name.kind != "source"), *listed]
    elif (match := _CALL.fullmatch(code)):
        names.append(DocName("function", match.group(1), where))
    elif (keys := _setting_keys(code)):
        names += [DocName("key", key, where) for key in keys if "key" in (_dotted_kind(key) or "")]
    elif _CAMEL.fullmatch(code) or _CONSTANT.fullmatch(code):
        names.append(DocName("identifier", code, where))
    # perhaps called: `engine_for(...)`; a list item's key (`contacts[].restitution`) is looked up in the items
    elif (match := re.fullmatch(r"(%s)(?:\(.*\))?" % _DOTTED.pattern, code.replace("[]", ""))):
        dotted = match.group(1)
        if dotted.rsplit(".", 1)[1].lower() not in FILE_SUFFIXES and (kind := _dotted_kind(dotted)):
            names.append(DocName(kind, dotted, where))
    elif re.search(r"\s[-+*/=]\s", code):  # a formula: the config keys in it
        names += [DocName("key", token, where) for token in _KEY_TOKEN.findall(code)
                  if "key" in (_dotted_kind(token) or "")]
    return names


def _page_names(page: Path) -> list[DocName]:
    relative = page.relative_to(REPO_ROOT).as_posix()
    prose, blocks = _split_fences(page.read_text(encoding="utf-8"))
    names = []
    for number, code, before, after in _inline_spans(prose):
        names += _span_names(code, before, after, f"{relative}:{number}")
    for number, line in enumerate(prose, 1):
        if (match := re.fullmatch(r":::\s+([\w.]+)\s*", line)):  # mkdocstrings' API directives
            names.append(DocName("python", match.group(1), f"{relative}:{number}"))
    for first, language, lines in blocks:
        folder = ""
        for number, line in enumerate(lines, first):
            if not line[:1].isspace():  # a folder listing: a line's first column names what it describes
                folder = line.split()[0] if line.split() and line.split()[0].endswith("/") else ""
            command = line.split("#", 1)[0] if language in ("bash", "sh", "shell", "console") else line
            where = f"{relative}:{number}"
            names += _file_names(command, where, folder) + _command_names(command, where)
        if language in ("yaml", "yml"):
            keys = _mapping_keys(yaml.safe_load("\n".join(lines)))
            names += [DocName("key", key, f"{relative}:{first}") for key in keys
                      if key.split(".")[0] in _schema()["properties"]]
    return names


@functools.lru_cache(maxsize=None)
def doc_names() -> tuple[DocName, ...]:
    """Every name of the manual the checker checks."""
    return tuple(name for page in _doc_pages() for name in _page_names(page))


# --- What exists -----------------------------------------------------------------------------------------------------

@functools.lru_cache(maxsize=None)
def _schema() -> dict:
    return load_schema()  # the main schema with every case kind's fragment


def _schema_nodes(node) -> list[dict]:
    """A schema node and what it stands for: its $ref's definition, its array's items, its oneOf/anyOf/allOf."""
    if not isinstance(node, dict):
        return []
    found = [node]
    if "$ref" in node:
        found += _schema_nodes(_schema()["definitions"][node["$ref"].rsplit("/", 1)[1]])
    found += _schema_nodes(node.get("items"))
    for key in ("oneOf", "anyOf", "allOf"):
        for branch in node.get(key, []):
            found += _schema_nodes(branch)
    return found


def _schema_children(node: dict, part: str) -> list[dict]:
    """The nodes key ``part`` of ``node`` leads to: a declared property, or any name its additionalProperties take
    (within a propertyNames enum); a placeholder (`<name>`, `*`) leads to every child."""
    children = []
    for expanded in _schema_nodes(node):
        properties = expanded.get("properties", {})
        additional = expanded.get("additionalProperties")
        additional = additional if isinstance(additional, dict) else None
        allowed = (expanded.get("propertyNames") or {}).get("enum")
        if _PLACEHOLDER.fullmatch(part):
            children += [*properties.values(), *([additional] if additional else [])]
        elif part in properties:
            children.append(properties[part])
        elif additional and (allowed is None or part in allowed):
            children.append(additional)
    return children


def _key_exists(parts: list[str], node: dict) -> bool:
    nodes = [node]
    for part in parts:
        nodes = [child for node in nodes for child in _schema_children(node, part)]
        if not nodes:
            return False
    return True


@functools.lru_cache(maxsize=None)
def _nested_key_nodes() -> dict[str, list[dict]]:
    """``{key: [the schema nodes it names]}`` of every key below the top-level sections, for the keys the manual
    gives relative to their section (`fill.balance_planes`, `davis.choice`)."""
    found: dict[str, list[dict]] = {}
    seen: set[int] = set()

    def walk(node):
        for expanded in _schema_nodes(node):
            if id(expanded) not in seen:
                seen.add(id(expanded))
                for name, child in expanded.get("properties", {}).items():
                    found.setdefault(name, []).append(child)
                    walk(child)
                walk(expanded.get("additionalProperties"))

    for section in _schema()["properties"].values():
        walk(section)
    return found


#: Keys of earlier versions the manual may name as such: the config refuses them with their new name.
RETIRED_KEYS = frozenset(".".join(path) for path in (*RENAMED_KEYS, *REPLACED_KEYS))


def _key_resolves(name: str) -> bool:
    parts = name.split(".")
    if parts[0] in _schema()["properties"] or _PLACEHOLDER.fullmatch(parts[0]):
        return name in RETIRED_KEYS or _key_exists(parts, _schema())
    return any(_key_exists(parts[1:], node) for node in _nested_key_nodes().get(parts[0], []))


def _import(name: str):
    """The module ``name``, or None when there is none (an error inside an existing module is raised)."""
    try:
        return importlib.import_module(name)
    except ModuleNotFoundError as error:
        if error.name and (name == error.name or name.startswith(error.name + ".")):
            return None
        raise


def _has_attributes(found, attributes: list[str]) -> bool:
    for attribute in attributes:
        if hasattr(found, attribute):
            found = getattr(found, attribute)
        elif isinstance(found, type) and any(attribute in vars(klass).get("__annotations__", {})
                                             for klass in found.__mro__):
            return attribute == attributes[-1]  # an instance's field: nothing to look into below it
        else:
            return False
    return True


def _python_resolves(name: str) -> bool:
    """Import the longest importable module prefix of ``name`` and get the rest as attributes; a name that starts
    with a module's last part (`physics.free_fall_time`) is looked up in every module of that name."""
    parts = name.split(".")
    if parts[0] not in PACKAGES:
        return any(_python_resolves(".".join([module, *parts[1:]])) for module in _project_modules().get(parts[0], []))
    for cut in range(len(parts), 0, -1):
        if (module := _import(".".join(parts[:cut]))) is not None:
            return _has_attributes(module, parts[cut:])
    return False


@functools.lru_cache(maxsize=None)
def _project_modules() -> dict[str, list[str]]:
    """``{last part of a module's name: [module names]}`` of the project's packages."""
    found: dict[str, list[str]] = {}
    for package in PACKAGES:
        for path in (REPO_ROOT / package).rglob("*.py"):
            parts = path.relative_to(REPO_ROOT).with_suffix("").parts
            parts = parts[:-1] if parts[-1] == "__init__" else parts
            found.setdefault(parts[-1], []).append(".".join(parts))
    return found


@functools.lru_cache(maxsize=None)
def _project_definitions() -> dict[str, list[str]]:
    """``{class or module-level constant: [modules defining it]}`` of the project's packages."""
    found: dict[str, list[str]] = {}
    definition = re.compile(r"^(?:class\s+(\w+)|([A-Z][A-Z0-9_]*)\s*(?::[^=\n]*)?=)", re.M)
    for package in PACKAGES:
        for path in (REPO_ROOT / package).rglob("*.py"):
            module = ".".join(path.relative_to(REPO_ROOT).with_suffix("").parts).removesuffix(".__init__")
            for match in definition.finditer(path.read_text(encoding="utf-8")):
                found.setdefault(match.group(1) or match.group(2), []).append(module)
    return found


@functools.lru_cache(maxsize=None)
def _project_functions() -> frozenset[str]:
    """The names of the functions and methods the project's packages define."""
    return frozenset(name for package in PACKAGES for path in (REPO_ROOT / package).rglob("*.py")
                     for name in re.findall(r"^\s*def\s+(\w+)", path.read_text(encoding="utf-8"), re.M))


def _identifier_resolves(name: str) -> bool:
    """A class (`RunRecord`, `Engine.measured_cost`) or a module-level constant (`CASE_KINDS`) of the project."""
    base, _, attribute = name.partition(".")
    return any(_has_attributes(_import(module), [base, *([attribute] if attribute else [])])
               for module in _project_definitions().get(base, []))


@functools.lru_cache(maxsize=None)
def _source_files() -> frozenset[str]:
    """The names of the repository's source files."""
    return frozenset(path.name for root in PATH_ROOTS for suffix in SOURCE_SUFFIXES
                     for path in (REPO_ROOT / root).rglob(f"*.{suffix}"))


def _defined_in(name: str) -> bool:
    """`name in path`: the path exists and its text (a folder: the text of a file below it) has the name."""
    word, _, path = name.partition(" in ")
    target = REPO_ROOT / path
    files = sorted(target.rglob("*")) if target.is_dir() else [target] if target.is_file() else []
    return any(re.search(rf"\b{re.escape(word)}\b", file.read_text(encoding="utf-8", errors="replace"))
               for file in files if file.is_file())


@functools.lru_cache(maxsize=None)
def _rule_patterns() -> tuple[re.Pattern, ...]:
    """The workflow's rules: `rule <name>:`, and the rules a loop names (`name: f"validate_{_group}"`, which any
    name in place of each {...} matches)."""
    texts = [path.read_text(encoding="utf-8")
             for path in [REPO_ROOT / "Snakefile", *sorted((REPO_ROOT / "siloflow" / "workflow" / "rules").glob("*.smk"))]]
    static = {name for text in texts for name in re.findall(r"^\s*rule\s+(\w+)\s*:", text, re.M)}
    built = {name for text in texts
             for name in re.findall(r"^\s*rule\s*:\s*\n\s*name\s*:\s*f?[\"']([^\"']+)[\"']", text, re.M)}
    return tuple(re.compile(re.escape(name)) for name in static) + tuple(
        re.compile("".join(r"\w+" if piece.startswith("{") else re.escape(piece)
                           for piece in re.split(r"(\{[^}]*\})", name) if piece)) for name in built)


@functools.lru_cache(maxsize=None)
def _variables_text() -> str:
    """Where a variable the manual sets may be read: the Makefile and the Python source."""
    return "\n".join(path.read_text(encoding="utf-8") for path in [REPO_ROOT / "Makefile", *(
        path for root in PATH_ROOTS for path in (REPO_ROOT / root).rglob("*.py"))])


def _make_target_exists(name: str) -> bool:
    return name in re.findall(r"^([\w.-]+)\s*:(?!=)", (REPO_ROOT / "Makefile").read_text(encoding="utf-8"), re.M)


def _group_resolves(name: str) -> bool:
    try:
        group_of_part(name)
    except ValueError:
        return False
    return True


RESOLVERS = {
    "path": lambda name: (REPO_ROOT / name).is_dir() if name.endswith("/") else (REPO_ROOT / name).exists(),
    "source": lambda name: name in _source_files(),
    "python": _python_resolves,
    "key": _key_resolves,
    "rule": lambda name: any(pattern.fullmatch(name) for pattern in _rule_patterns()),
    "make": _make_target_exists,
    "variable": lambda name: re.search(rf"\b{name}\b", _variables_text()) is not None,
    "group": _group_resolves,
    "identifier": _identifier_resolves,
    "function": lambda name: name in _project_functions(),
    "defined": _defined_in,
}


def resolves(name: DocName) -> bool:
    """Whether what ``name`` names exists (as any of its kinds)."""
    return any(RESOLVERS[kind](name.name) for kind in name.kind.split("|"))


def test_every_module_rule_and_config_key_the_docs_name_exists():
    names = doc_names()
    kinds = {kind for name in names for kind in name.kind.split("|")}
    assert kinds >= {"path", "python", "key", "rule"}, f"the checker finds none of some kinds in the docs: {kinds}"
    unresolved = [name for name in names if name.name not in DELIBERATELY_UNDEFINED and not resolves(name)]
    assert not unresolved, ("names in the docs that nothing in the repository defines (correct the docs; or, if one "
                            "is not the project's name, teach this checker so):\n"
                            + "\n".join(f"  {name.where}: {name.kind} {name.name}" for name in unresolved))


def test_the_deliberately_undefined_names_are_still_in_the_docs_and_still_undefined():
    given = {name.name: name for name in doc_names()}
    for name in DELIBERATELY_UNDEFINED:
        assert name in given, f"{name} is no longer in the docs: drop it from DELIBERATELY_UNDEFINED"
        assert not resolves(given[name]), f"{name} now exists: drop it from DELIBERATELY_UNDEFINED"


@pytest.mark.parametrize("markdown, exists", [
    ("`siloflow/engines/preflight.py` and `siloflow/templates/liggghts/`", True),
    ("`engines/preflght.py`", False),
    ("`siloflow.analysis.numerics.force_balance.settled_fill_balance`", True),
    ("`siloflow.analysis.numerics.force_balance.settled_balance`", False),
    ("`python -m engines.planing config/config.yaml`", False),
    ("rule `silo_run`, the `silo_metrics` rule, `rule validate_silo_series`", True),
    ("rules `silo_run` and `silo_runs`", False),
    ("`silo_flat.fill.zone_height`, `materials.hdpe.density`, `particle_models.<name>.spheres`", True),
    ("`jenike.sweep.*`, `<case>.engine`, `tracer.start_recirculations + shortcut.residence_times`", True),
    ("`silo_flat.fill.zone_heigth`", False),
    ("`contacts[].restitution`, `particle_models.<name>.spheres[].radius`", True),
    ("`contacts[].restitutoin`", False),
    ("`fill.zone_heigth: 0.02`", False),
    ("`estimates.seconds_per_sphere_step_by_case.blender`", True),
    ("`estimates.seconds_per_sphere_step_by_case.hopper`", False),  # not one of its propertyNames
    ("`PlanarField.kind` and `CASE_KINDS`", True),
    ("`PlanarField.knd`", False),
    ("`stable_timestep` in `siloflow/model/cases/particles.py`", False),
    ("`siloflow/analysis/studies/blender/`: `modes.py`, `mode.py`", False),
    ("`make validate GROUP=silo_2`", True),
    ("`make validate GROUP=hopper_1`", False),
])
def test_the_checker_tells_a_stale_name_from_a_current_one(markdown, exists):
    names = [name for line, code, before, after in _inline_spans([markdown])
             for name in _span_names(code, before, after, f"example:{line}")]
    assert names, f"the checker reads no name in {markdown!r}"
    assert all(resolves(name) for name in names) == exists, [(name, resolves(name)) for name in names]
