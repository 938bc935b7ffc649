"""The documentation's code runs: the tutorial and the how-to guides' blocks, executed.

Every ```sh and ```python block of a page listed below is run in order, in a fresh
folder, unless the line before its fence is ``<!-- skip-test: why -->``. A shell block
may hold ``suds-exp ...`` commands (run through typer's CliRunner, each must exit 0),
``export NAME=VALUE`` and comments; any other line fails the test, so a page cannot
show a command the test silently ignores. Each Python block runs on its own in a fresh
interpreter (in the page's folder, after the blocks before it), as a reader pasting it
would run it: a block that needs an import from an earlier one fails. A page marked
``<!-- executed -->`` is a notebook (docs/hooks/executed.py): its blocks share one
namespace, as a notebook's cells do.
"""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest
from typer.testing import CliRunner

from cli import app

DOCS = Path(__file__).resolve().parents[1] / "docs"
FENCE = re.compile(
    r"(?P<before>^[^\n]*\n)?^```(?P<lang>sh|python)[^\n]*\n(?P<body>.*?)^```\s*$",
    re.MULTILINE | re.DOTALL,
)


def blocks(page: str) -> list[tuple[str, str]]:
    """(language, code) of every block of ``page`` that is to be run, in order."""
    text = (DOCS / page).read_text()
    out = []
    for m in FENCE.finditer(text):
        if (m.group("before") or "").startswith("<!-- skip-test"):
            continue
        out.append((m.group("lang"), m.group("body")))
    return out


def shell_commands(code: str) -> list[list[str]]:
    """The commands of a shell block, continuation lines joined, comments dropped."""
    joined = re.sub(r"\\\n\s*", " ", code)
    commands = []
    for line in joined.splitlines():
        line = line.strip()
        if not line or line.startswith("#"):
            continue
        commands.append(shlex.split(line, comments=True))
    return commands


def run_page(page: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("COLUMNS", "120")
    runner = CliRunner()
    namespace: dict = {"__name__": "__docs__"}
    notebook = "<!-- executed -->" in (DOCS / page).read_text()
    ran = 0
    for lang, code in blocks(page):
        if lang == "python" and notebook:
            exec(compile(code, f"{page} (python block)", "exec"), namespace)
            ran += 1
            continue
        if lang == "python":
            done = subprocess.run(
                [sys.executable, "-c", code],
                capture_output=True,
                text=True,
                env={**os.environ, "PYTHONPATH": str(DOCS.parent)},
                timeout=600,
            )
            assert done.returncode == 0, (
                f"{page}: a python block failed on its own:\n{code}\n{done.stderr}"
            )
            ran += 1
            continue
        for argv in shell_commands(code):
            if argv[0] == "export":
                name, _, value = argv[1].partition("=")
                monkeypatch.setenv(name, value)
                continue
            assert argv[0] == "suds-exp", f"{page}: cannot run {' '.join(argv)!r} in the test"
            result = runner.invoke(app, argv[1:], env=dict(os.environ))
            assert result.exit_code == 0, (
                f"{page}: {shlex.join(argv)} exited {result.exit_code}:\n{result.output}"
            )
            ran += 1
    assert ran, f"{page}: no block was run"


def test_the_tutorial_runs(tmp_path, monkeypatch):
    run_page("tutorial.md", tmp_path, monkeypatch)


@pytest.mark.parametrize(
    "page",
    ["how-to/own-recordings.md", "how-to/sql-and-pandas.md", "how-to/notebooks.md"],
)
def test_how_to_guides_run(page, tmp_path, monkeypatch):
    run_page(page, tmp_path, monkeypatch)


@pytest.mark.slow
@pytest.mark.parametrize(
    "page",
    [
        "how-to/discrepancy.md",
        "how-to/learner-survey.md",
        "how-to/streams.md",
        "how-to/own-experiment.md",
        "how-to/plan-your-next-recording.md",
    ],
)
def test_long_how_to_guides_run(page, tmp_path, monkeypatch):
    run_page(page, tmp_path, monkeypatch)


def test_skipped_blocks_say_why():
    for page in DOCS.rglob("*.md"):
        for line in page.read_text().splitlines():
            if line.startswith("<!-- skip-test"):
                assert re.match(r"<!-- skip-test: \S.* -->$", line), f"{page}: {line}"


def generators():
    """docs/hooks/suds_docs.py, the MkDocs hook that writes the generated reference."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("suds_docs", DOCS / "hooks" / "suds_docs.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_every_command_is_in_the_cli_reference():
    import typer

    page = generators().cli()
    for name in typer.main.get_command(app).commands:
        assert f"## `suds-exp {name}`" in page, name


def test_every_table_view_and_parameter_is_in_the_reference(tmp_path, monkeypatch):
    from suds_exp.preprocess.params import DEFAULTS
    from suds_exp.store import Store

    gen = generators()
    monkeypatch.syspath_prepend(str(DOCS / "hooks"))
    page = gen.database()
    store = Store(tmp_path / "x.duckdb")
    store.upgrade()
    names = store.query_df(
        "SELECT table_name FROM information_schema.tables WHERE table_schema = 'main'"
    ).table_name
    assert len(names) >= 20
    for name in names:
        assert f"### `{name}`" in page, name
    params = gen.preprocessing_parameters()
    for key in DEFAULTS:
        assert f"| `{key}` |" in params, key


def test_the_site_check_finds_folder_links_missing_files_and_orphans(tmp_path):
    """`docs/hooks/check_site.py` (run by `make docs` on the built site) flags what a
    reader opening the files would hit."""
    import importlib.util

    path = DOCS / "hooks" / "check_site.py"
    spec = importlib.util.spec_from_file_location("check_site", path)
    check_site = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(check_site)
    (tmp_path / "sub").mkdir()
    (tmp_path / "index.html").write_text(
        '<a href="sub/">x</a><a href="gone.html#a">y</a><a href="ok.html">z</a>'
        '<img src="data:image/png;base64,AA"><a href="https://example.org/">w</a>'
    )
    (tmp_path / "ok.html").write_text('<a href="index.html">back</a><a href="#top">top</a>')
    (tmp_path / "orphan.html").write_text("<p>alone</p>")
    assert check_site.check(tmp_path) == [
        "index.html: sub/ -> a folder",
        "index.html: gone.html#a -> missing",
        "orphan.html: not reached from index.html",
    ]
