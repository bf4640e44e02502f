"""The documentation cannot drift: README.md and docs/*.md against the code they describe.

* ``docs/configuration.md`` is exactly what :mod:`demcal.core.config_reference` renders from the
  schema now, and names every key of the schema.
* Every command shown in code (inline or in a block) exists: ``make X`` targets of the Makefile,
  ``snakemake ... TARGET`` rules, ``--configfile`` files, repository paths (``scripts/...``,
  ``config/...``, ``demcal/...``, ...) and ``demcal.*`` modules and names.
* Every relative link (and its ``#anchor``) between README.md and the docs pages resolves.
* README.md stays a front page (under 250 lines).

The checkers are tested on made-up text too, so that a broken command is known to fail.
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from pathlib import Path

import pytest

from demcal.core.config_reference import key_paths, main, render_markdown

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"
PAGES = [ROOT / "README.md", *sorted(DOCS.glob("*.md"))]
README_MAX_LINES = 250

# Repository paths that a doc may show in code; anything else (results/, logs/, ...) is output.
CHECKED_DIRS = (
    "config",
    "demcal",
    "dem_engine",
    "docs",
    "scripts",
    "templates",
    "tests",
    "workflow",
)
_PATH = re.compile(r"(?<![\w./-])((?:" + "|".join(CHECKED_DIRS) + r")/[\w./<>*{}-]*)")
_MODULE = re.compile(r"(?<![\w./-])(demcal(?:\.\w+)+)")
_LINK = re.compile(r"(?<!!)\[[^\]]*\]\(([^)\s]+)\)")
_FENCE = re.compile(r"^```[^\n]*\n(.*?)^```[ \t]*$", re.MULTILINE | re.DOTALL)
_INLINE = re.compile(r"`([^`\n]+)`")
_SEPARATORS = {"&&", "||", ";", "|", "\\"}

# Snakemake options that take values: one value, or (greedy, as Snakemake parses them) several.
_SNAKEMAKE_ONE = {
    "--profile",
    "-s",
    "--snakefile",
    "-d",
    "--directory",
    "--report",
    "--until",
    "--omit-from",
    "--executor",
    "-e",
    "--latency-wait",
}
_SNAKEMAKE_MANY = {
    "--configfile",
    "--configfiles",
    "--config",
    "-C",
    "--default-resources",
    "--resources",
    "--rerun-triggers",
    "--set-threads",
    "--set-resources",
    "--forcerun",
    "-R",
    "--allowed-rules",
}
_SNAKEMAKE_COUNT = {"--cores", "-c", "--jobs", "-j"}


# ---- extraction -----------------------------------------------------------------------------


def code_snippets(text: str) -> list[str]:
    """Code of a Markdown text: fenced blocks (continuation lines joined) and inline spans."""
    blocks = [m.group(1).replace("\\\n", " ") for m in _FENCE.finditer(text)]
    prose = _FENCE.sub("", text)
    return blocks + _INLINE.findall(prose)


def _commands(snippet: str, program: str) -> Iterator[list[str]]:
    """Argument lists of every call of ``program`` in a snippet (up to a separator/comment)."""
    for line in snippet.splitlines():
        tokens = line.split()
        for i, token in enumerate(tokens):
            if token != program and not token.endswith(f"/{program}"):
                continue
            before = tokens[i - 1] if i else "&&"
            if before not in _SEPARATORS and not re.fullmatch(r"[A-Z_]+=\S*", before):
                continue  # a command starts a line, follows a separator or an ENV=value
            args = []
            for arg in tokens[i + 1 :]:
                if arg in _SEPARATORS or arg.startswith("#"):
                    break
                args.append(arg.strip("`"))
            yield args


def make_targets_in(snippet: str) -> list[str]:
    """Targets named by ``make ...`` calls (``VAR=value`` and options skipped)."""
    targets = []
    for args in _commands(snippet, "make"):
        for arg in args:
            if "=" in arg or arg.startswith("-"):
                continue
            targets.append(arg)
    return targets


def snakemake_calls_in(snippet: str) -> list[tuple[list[str], list[str]]]:
    """Per ``snakemake`` call: its targets and its ``--configfile`` values."""
    calls = []
    for args in _commands(snippet, "snakemake"):
        targets: list[str] = []
        configfiles: list[str] = []
        i = 0
        while i < len(args):
            arg = args[i]
            if arg in _SNAKEMAKE_ONE:
                i += 2
                continue
            if arg in _SNAKEMAKE_COUNT:
                i += 2 if i + 1 < len(args) and re.fullmatch(r"\d+|all", args[i + 1]) else 1
                continue
            if arg in _SNAKEMAKE_MANY:
                i += 1
                while i < len(args) and not args[i].startswith("-"):
                    if arg in {"--configfile", "--configfiles"}:
                        configfiles.append(args[i])
                    i += 1
                continue
            if not arg.startswith("-"):
                targets.append(arg)
            i += 1
        calls.append((targets, configfiles))
    return calls


def makefile_targets() -> set[str]:
    text = (ROOT / "Makefile").read_text()
    targets = set()
    for m in re.finditer(r"^([A-Za-z0-9_.-][A-Za-z0-9_. -]*?)\s*:(?!=)", text, re.MULTILINE):
        targets.update(m.group(1).split())
    for m in re.finditer(r"^\.PHONY\s*:(.*)$", text, re.MULTILINE):
        targets.update(m.group(1).split())
    return targets


def snakemake_rules() -> set[str]:
    files = [ROOT / "Snakefile", *sorted((ROOT / "workflow" / "rules").glob("*.smk"))]
    pattern = re.compile(r"^(?:rule|checkpoint)\s+(\w+)\s*:", re.MULTILINE)
    return {name for f in files for name in pattern.findall(f.read_text())}


def github_anchors(text: str) -> set[str]:
    """Anchors GitHub gives the headings of a Markdown text (duplicates get -1, -2, ...)."""
    anchors: set[str] = set()
    for line in _FENCE.sub("", text).splitlines():
        m = re.match(r"^#{1,6}\s+(.*?)\s*#*\s*$", line)
        if not m:
            continue
        base = re.sub(r"[^\w\- ]", "", m.group(1).lower()).replace(" ", "-")
        slug, n = base, 0
        while slug in anchors:
            n += 1
            slug = f"{base}-{n}"
        anchors.add(slug)
    return anchors


# ---- checks ---------------------------------------------------------------------------------


def _path_exists(path: str) -> bool:
    pattern = re.sub(r"<[^>]*>|\{[^}]*\}", "*", path.rstrip(".,:;"))
    if any(c in pattern for c in "*?["):
        return any(ROOT.glob(pattern.rstrip("/")))
    return (ROOT / pattern).exists()


def _module_problem(dotted: str) -> str | None:
    """Why ``demcal.a.b[.name]`` does not resolve to a package, module or name in it, or None."""
    parts = dotted.split(".")
    here = ROOT / parts[0]
    for i, part in enumerate(parts[1:], start=1):
        if (here / part).is_dir() and (here / part / "__init__.py").is_file():
            here = here / part
            continue
        if (here / f"{part}.py").is_file():
            here = here / f"{part}.py"
            rest = parts[i + 1 :]
            break
        rest = parts[i:]
        here = here / "__init__.py"
        break
    else:
        return None
    if not rest:
        return None
    name = rest[0]
    source = here.read_text() if here.is_file() else ""
    defined = re.compile(rf"^(?:def|class)\s+{name}\b|^{name}\s*[:=]|\bimport\b.*\b{name}\b", re.M)
    if not defined.search(source):
        return f"`{dotted}`: no module or name `{name}` in {here.relative_to(ROOT)}"
    return None


def doc_problems(text: str, page: Path) -> list[str]:
    """Every command, path, module and link of a Markdown page that does not exist."""
    problems = []
    targets = makefile_targets()
    rules = snakemake_rules()
    for snippet in code_snippets(text):
        for target in make_targets_in(snippet):
            if target not in targets:
                problems.append(f"`make {target}`: no such target in the Makefile")
        for call_targets, configfiles in snakemake_calls_in(snippet):
            for target in call_targets:
                if re.fullmatch(r"\w+", target) and target not in rules:
                    problems.append(f"`snakemake ... {target}`: no such rule")
            for configfile in configfiles:
                if configfile.startswith("config/") and not _path_exists(configfile):
                    problems.append(f"`--configfile {configfile}`: no such file")
        for path in _PATH.findall(snippet):
            if not _path_exists(path):
                problems.append(f"`{path}`: no such file or directory")
        for dotted in _MODULE.findall(snippet):
            if problem := _module_problem(dotted):
                problems.append(problem)
    for link in _LINK.findall(_FENCE.sub("", _INLINE.sub("``", text))):
        if re.match(r"[a-z]+:", link):
            continue  # http(s), mailto
        target, _, anchor = link.partition("#")
        file = (page.parent / target).resolve() if target else page
        if not file.exists():
            problems.append(f"link `{link}`: {target} does not exist")
        elif anchor and file.suffix == ".md" and anchor not in github_anchors(file.read_text()):
            problems.append(f"link `{link}`: no heading #{anchor} in {file.name}")
    return problems


# ---- the configuration reference ------------------------------------------------------------


def test_configuration_reference_is_current():
    written = (DOCS / "configuration.md").read_text()
    assert written == render_markdown(), (
        "docs/configuration.md differs from the schema; regenerate it with `make docs`"
    )


def test_every_schema_key_is_in_the_reference():
    text = (DOCS / "configuration.md").read_text()
    paths = key_paths()
    assert {"engine.command", "discrepancy.extended.n", "discrepancy.candidates[].name"} <= set(
        paths
    )
    missing = [p for p in paths if f"`{p}`" not in text]
    assert not missing, f"keys missing from docs/configuration.md: {missing}"


def test_reference_follows_a_schema_change(tmp_path):
    schema = {
        "description": "Test schema.",
        "properties": {
            "alpha": {
                "description": "An object.",
                "type": "object",
                "default": {},
                "properties": {
                    "beta": {
                        "description": "A bounded | integer.",
                        "type": "integer",
                        "minimum": 1,
                        "exclusiveMaximum": 10,
                        "default": 2,
                    },
                    "mode": {"description": "A choice.", "enum": ["a", "b"], "default": "a"},
                },
            },
        },
    }
    text = render_markdown(schema)
    assert "## `alpha`" in text
    assert "| `alpha.beta` | integer | `2` | `[1, 10)` | A bounded \\| integer. |" in text
    assert "| `alpha.mode` |  | `a` | `a`, `b` | A choice. |" in text
    assert key_paths(schema) == ["alpha", "alpha.beta", "alpha.mode"]
    out = tmp_path / "configuration.md"
    assert main(["--output", str(out)]) == 0
    assert out.read_text() == render_markdown()


# ---- commands, paths and links in the docs ---------------------------------------------------


def test_pages_exist():
    names = {p.name for p in PAGES}
    expected = {
        "README.md",
        "quickstart.md",
        "configuration.md",
        "virtual-tests.md",
        "convergence.md",
        "identification.md",
        "discrepancy.md",
        "cluster.md",
        "engine.md",
        "benchmarks.md",
        "development.md",
    }
    assert expected <= names


@pytest.mark.parametrize("page", PAGES, ids=lambda p: str(p.relative_to(ROOT)))
def test_commands_paths_and_links_exist(page):
    problems = doc_problems(page.read_text(), page)
    assert not problems, f"{page.relative_to(ROOT)}:\n  " + "\n  ".join(problems)


def test_the_docs_show_the_main_commands():
    """Guards the extraction itself: the commands the docs are known to show are found."""
    snippets = [s for page in PAGES for s in code_snippets(page.read_text())]
    made = {t for s in snippets for t in make_targets_in(s)}
    assert {"run", "test", "setup", "docs", "lint", "bench"} <= made
    targets = {t for s in snippets for call, _ in snakemake_calls_in(s) for t in call}
    assert "discrepancy" in targets
    configfiles = {c for s in snippets for _, files in snakemake_calls_in(s) for c in files}
    assert {"config/tiny.yaml", "config/paper.yaml"} <= configfiles


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("Run `make nonexistent` first.", "make nonexistent"),
        ("```bash\nmake run CORES=2 && make nonexistent\n```\n", "make nonexistent"),
        ("`python scripts/no_such_script.py --help`", "scripts/no_such_script.py"),
        ("`snakemake --cores 2 --force-use-threads no_such_rule`", "no_such_rule"),
        ("`snakemake --configfile config/no_such.yaml --cores 1`", "config/no_such.yaml"),
        ("```\nsnakemake -s Snakefile \\\n    --cores 2 no_such_rule\n```\n", "no_such_rule"),
        ("See `demcal/no_such_module.py`.", "demcal/no_such_module.py"),
        ("`python -m demcal.core.no_such_module`", "no_such_module"),
        ("`demcal.virtual_tests.pictures.no_such_function(x)`", "no_such_function"),
        ("See [the guide](no-such-page.md).", "no-such-page.md"),
        ("See [the guide](quickstart.md#no-such-heading).", "no-such-heading"),
    ],
)
def test_checker_catches_broken_references(text, expected):
    problems = doc_problems(text, DOCS / "made-up.md")
    assert any(expected in p for p in problems), problems


@pytest.mark.parametrize(
    "text",
    [
        "`make run CORES=2`, `make test` and `make` alone",
        "To make the runs faster, use `cmake` and `make_synthetic_experiment.py`.",
        "```bash\nsnakemake --cores 2 --force-use-threads discrepancy   # note\n```\n",
        "`snakemake --profile workflow/profiles/slurm --configfile config/paper.yaml`",
        "`config/experiments/*.yaml`, `workflow/profiles/<name>/config.yaml`, `results/x.csv`",
        "`demcal.virtual_tests.pictures.heap_picture(case_dir, png)`",
        "[Quick start](quickstart.md#what-you-get), [web](https://example.org/x)",
    ],
)
def test_checker_accepts_valid_references(text):
    assert doc_problems(text, DOCS / "made-up.md") == []


def test_readme_is_a_front_page():
    lines = (ROOT / "README.md").read_text().splitlines()
    assert len(lines) < README_MAX_LINES, f"README.md has {len(lines)} lines"
