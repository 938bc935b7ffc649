"""The package as installed: its package list, version, `python -m suds_exp`, and the
schema it creates from its migrations (package data), or refuses to create without them.

The same checks run on a built wheel installed outside the checkout in .ci/wheel_check.sh.
"""

from __future__ import annotations

import ast
import hashlib
import json
import re
import subprocess
import sys
import tomllib
from importlib.metadata import packages_distributions, version
from pathlib import Path

from typer.testing import CliRunner

import suds_exp
from cli import app
from suds_exp.store import migrate
from suds_exp.testing.migration_text import created_by_migrations

REPO = Path(__file__).resolve().parents[1]
runner = CliRunner()


def pyproject() -> dict:
    return tomllib.loads((REPO / "pyproject.toml").read_text(encoding="utf-8"))


def test_every_package_folder_is_listed_for_the_wheel():
    listed = set(pyproject()["tool"]["setuptools"]["packages"])
    folders = {
        ".".join(p.parent.relative_to(REPO).parts) for p in (REPO / "suds_exp").rglob("__init__.py")
    }
    assert listed == folders | {"suds_exp.migrations", "suds_exp.app"}


def test_version_is_the_installed_metadata():
    declared = pyproject()["project"]["version"]
    assert suds_exp.__version__ == version("suds-exp") == declared
    result = runner.invoke(app, ["--version"])
    assert result.exit_code == 0 and result.stdout.strip() == f"suds-exp {declared}"


def test_python_m_suds_exp_runs_the_same_app():
    result = subprocess.run(
        [sys.executable, "-m", "suds_exp", "--help"],
        capture_output=True,
        text=True,
        timeout=120,
        cwd=REPO,
    )
    assert result.returncode == 0, result.stderr
    same = runner.invoke(app, ["--help"]).stdout
    commands = re.findall(r"│ (\w+) ", same)
    assert len(commands) > 10
    for name in commands:
        assert f"│ {name} " in result.stdout, name


def catalog(db: Path) -> tuple[set[str], set[str], list[int]]:
    """Tables, views and applied migration versions of ``db``, through `suds-exp sql`."""
    query = (
        "SELECT table_name, table_type FROM information_schema.tables WHERE table_schema = 'main'"
    )
    result = runner.invoke(app, ["sql", query, "--db", str(db), "--json"])
    assert result.exit_code == 0, result.stderr
    rows = json.loads(result.stdout)
    versions = runner.invoke(
        app, ["sql", "SELECT version FROM schema_migrations", "--db", str(db), "--json"]
    )
    return (
        {r["table_name"] for r in rows if r["table_type"] == "BASE TABLE"},
        {r["table_name"] for r in rows if r["table_type"] == "VIEW"},
        sorted(r["version"] for r in json.loads(versions.stdout)),
    )


def test_init_creates_every_table_and_view(db):
    result = runner.invoke(app, ["init", "--db", str(db)])
    assert result.exit_code == 0, result.stderr
    tables, views, versions = catalog(db)
    expected_tables, expected_views = created_by_migrations(REPO / "migrations")
    assert len(expected_tables) > 15 and len(expected_views) >= 4
    assert (tables, views) == (expected_tables, expected_views)
    files = sorted(REPO.glob("migrations/*.sql"))
    assert versions == [int(p.name[:3]) for p in files]
    assert Path(str(migrate.migrations_dir())).resolve() == (REPO / "migrations").resolve()


def digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def refused(args: list[str]) -> str:
    result = runner.invoke(app, args)
    assert result.exit_code == 2, result.stdout
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    return lines[0]


def test_no_migration_files_is_refused_and_nothing_is_created(tmp_path, monkeypatch):
    empty = tmp_path / "no-migrations"
    empty.mkdir()
    monkeypatch.setenv("SUDS_MIGRATIONS", str(empty))
    db = tmp_path / "sub" / "new.duckdb"
    line = refused(["init", "--db", str(db)])
    assert "no migrations found" in line and "up to date" not in line
    assert not db.exists() and not db.parent.exists()


def test_missing_migrations_package_refuses_an_existing_database_untouched(db, monkeypatch):
    assert runner.invoke(app, ["init", "--db", str(db)]).exit_code == 0
    before = digest(db)
    # what an install without the package data looks like to the runner
    monkeypatch.setattr(migrate, "MIGRATIONS_PACKAGE", "suds_exp.no_such_migrations")
    for args in (["init"], ["sql", "SELECT 1"], ["trials"]):
        line = refused([*args, "--db", str(db)])
        assert "no migrations found" in line and "reinstall suds-exp" in line, args
    assert digest(db) == before


def test_builtin_body_descriptions_are_package_data():
    from suds_exp.body.description import BUILTIN, load_body

    for name in BUILTIN:
        assert load_body(name).name == name


def imported_modules(top_level_only: bool) -> set[str]:
    """Top-level names of the third-party modules that suds_exp/ and cli.py import
    (``top_level_only``: at module level, not inside a function)."""
    found = set()
    for path in [REPO / "cli.py", *(REPO / "suds_exp").rglob("*.py")]:
        tree = ast.parse(path.read_text(encoding="utf-8"))
        nodes = tree.body if top_level_only else ast.walk(tree)
        for node in nodes:
            if isinstance(node, ast.Import):
                found |= {a.name.split(".")[0] for a in node.names}
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                found.add(node.module.split(".")[0])
    return found - set(sys.stdlib_module_names) - {"suds_exp", "cli", "__future__"}


def distribution_names(requirements: list[str]) -> set[str]:
    return {re.sub(r"[-_.]+", "-", re.match(r"[\w.-]+", r).group()).lower() for r in requirements}


def test_every_imported_module_is_a_declared_dependency():
    project = pyproject()["project"]
    required = distribution_names(project["dependencies"])
    extras = distribution_names(
        [
            r
            for name, reqs in project["optional-dependencies"].items()
            if name != "dev"
            for r in reqs
        ]
    )
    of_module = packages_distributions()

    def dists(module: str) -> set[str]:
        return {re.sub(r"[-_.]+", "-", d).lower() for d in of_module.get(module, [])}

    for module in imported_modules(top_level_only=True):
        assert dists(module) & required, f"{module} is imported but not in dependencies"
    # a module imported only where it is used (dask) may be an optional extra instead
    for module in imported_modules(top_level_only=False):
        assert dists(module) & (required | extras), f"{module} is imported but not declared"
