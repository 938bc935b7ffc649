#!/usr/bin/env bash
# The package as a user gets it: build the sdist and (from it) the wheel, install the wheel
# into a fresh venv outside the checkout, and from an empty folder run a short quickstart
# with the installed package only: --version, python -m, init (every table and view of the
# checkout's migrations/ must exist), simulate --ingest, preprocess, a tiny run, report, sql.
#
# Usage: .ci/wheel_check.sh   (needs the dev venv, for `python -m build`: make .venv/.installed)
# Env:   PY (python for the fresh venv, default python3), KEEP=1 keeps the temporary folder.
set -euo pipefail

REPO="$(cd "$(dirname "$0")/.." && pwd)"
PY="${PY:-python3}"
WORK="$(mktemp -d)"
if [ "${KEEP:-0}" = 1 ]; then echo "wheel check: keeping $WORK"; else trap 'rm -rf "$WORK"' EXIT; fi
step() { printf '\n== wheel check (%d s): %s\n' "$SECONDS" "$*"; }

step "build the sdist, then the wheel from it"
"$REPO/.venv/bin/python" -m build --outdir "$WORK/dist" "$REPO" >"$WORK/build.log" 2>&1 \
  || { tail -30 "$WORK/build.log"; exit 1; }
SDIST=$(ls "$WORK"/dist/suds_exp-*.tar.gz)
WHEEL=$(ls "$WORK"/dist/suds_exp-*.whl)
ls -l "$SDIST" "$WHEEL"

step "what the wheel and the sdist hold"
"$PY" - "$REPO" "$SDIST" "$WHEEL" <<'EOF'
import sys, tarfile, zipfile
from pathlib import Path
repo, sdist, wheel = Path(sys.argv[1]), sys.argv[2], sys.argv[3]
sql = sorted(p.name for p in (repo / "migrations").glob("*.sql"))
in_wheel = zipfile.ZipFile(wheel).namelist()
in_sdist = tarfile.open(sdist).getnames()
for name in sql:
    assert f"suds_exp/migrations/{name}" in in_wheel, f"wheel lacks migration {name}"
    assert any(n.endswith(f"/migrations/{name}") for n in in_sdist), f"sdist lacks {name}"
for data in ("suds_exp/body/swimmer.toml", "suds_exp/__main__.py", "suds_exp/app/cli.py"):
    assert data in in_wheel, f"wheel lacks {data}"
assert any(n.endswith(".dist-info/licenses/LICENSE") for n in in_wheel), "wheel lacks LICENSE"
# cli.py goes in as suds_exp.app.cli: no generic top-level module in a user's site-packages,
# and the folder mapped to suds_exp.app (the repository's top) holds no other module
top = {n.split("/")[0] for n in in_wheel}
assert top <= {"suds_exp"} | {t for t in top if t.endswith((".dist-info", ".data"))}, top
app = [n for n in in_wheel if n.startswith("suds_exp/app/")]
assert app == ["suds_exp/app/cli.py"], app
print(f"wheel: {len(in_wheel)} files, {len(sql)} migrations, swimmer.toml, LICENSE, "
      "cli as suds_exp/app/cli.py; sdist too")
EOF

step "install the wheel into a fresh venv"
"$PY" -m venv "$WORK/venv"
# --no-compile: byte-compile only what the quickstart imports, not every dependency
"$WORK/venv/bin/python" -m pip install --quiet --disable-pip-version-check --no-compile \
  "$WHEEL" >"$WORK/install.log" 2>&1 \
  || { grep -v '^WARNING: Location' "$WORK/install.log" | tail -30; exit 1; }
BIN="$WORK/venv/bin"

# The quickstart sees the installed package only: no checkout on the path, no overrides,
# an empty folder outside the repository as the working directory.
mkdir "$WORK/run"
cd "$WORK/run"
unset PYTHONPATH SUDS_DB SUDS_MIGRATIONS
export PATH="$BIN:$PATH"

step "the installed package is the one imported"
python - <<'EOF'
import importlib.util, sys, suds_exp
import suds_exp.app.cli as cli
from importlib.resources import files
assert importlib.util.find_spec("cli") is None, "a top-level module cli is installed"
for module in (suds_exp, cli):
    assert module.__file__.startswith(sys.prefix), f"{module.__name__} from {module.__file__}"
print("imported from", suds_exp.__file__, "; migrations at", files("suds_exp.migrations"))
EOF

step "suds-exp --version; python -m suds_exp --help"
VERSION=$(python -c "import tomllib; print(tomllib.load(open('$REPO/pyproject.toml', 'rb'))['project']['version'])")
test "$(suds-exp --version)" = "suds-exp $VERSION"
suds-exp --version
python -m suds_exp --help >help.txt
grep -q "simulate" help.txt && grep -q "preprocess" help.txt
echo "python -m suds_exp --help: $(grep -c '│ [a-z]' help.txt) lines of commands"

step "a database without migrations is refused in one line, nothing created"
mkdir empty
if SUDS_MIGRATIONS="$PWD/empty" suds-exp init --db refused.duckdb 2>err.txt; then
  echo "init without migrations succeeded"; exit 1
fi
cat err.txt
test "$(wc -l <err.txt)" = 1 && grep -q "no migrations found" err.txt && test ! -e refused.duckdb

step "suds-exp init: every table and view of the migrations"
suds-exp init --db q.duckdb
suds-exp sql "SELECT table_name, table_type FROM information_schema.tables WHERE table_schema = 'main'" \
  --db q.duckdb --json >catalog.json
python - "$REPO" <<'EOF'
import json, sys
from pathlib import Path
from suds_exp.testing.migration_text import created_by_migrations
tables, views = created_by_migrations(Path(sys.argv[1], "migrations"))
rows = json.load(open("catalog.json"))
got_t = {r["table_name"] for r in rows if r["table_type"] == "BASE TABLE"}
got_v = {r["table_name"] for r in rows if r["table_type"] == "VIEW"}
assert got_t == tables, f"tables: missing {tables - got_t}, unexpected {got_t - tables}"
assert got_v == views, f"views: missing {views - got_v}, unexpected {got_v - views}"
print(f"{len(got_t)} tables and {len(got_v)} views, as the migrations create them")
EOF

step "simulate --ingest (2 gaits x 1 frequency x 2 repeats, 6 cycles)"
suds-exp simulate --out sim-data --gaits O,D+ --freqs 1 --repeats 2 --cycles 6:6 --seed 0 \
  --ingest --db q.duckdb --quiet

step "preprocess with the built-in body description"
suds-exp preprocess --name quick --body swimmer --db q.duckdb --quiet

# 2 draws: the report's GLM needs 10 or more results at its training size
step "a tiny run: two learners, 2 draws, 2 training cycles"
suds-exp run quick --prep quick --models TLS,TLS+SUDS --boots 2 --train-cycles 2 --sweep 1 \
  --db q.duckdb --quiet

step "report and sql"
suds-exp report quick --out report --db q.duckdb
test -s report/index.html
ls report
suds-exp sql "SELECT model, count(*) AS n, median(rmse_vx) AS median_rmse_vx FROM results GROUP BY model ORDER BY model" \
  --db q.duckdb
N=$(suds-exp sql "SELECT count(*) AS n FROM results" --db q.duckdb --json | python -c "import json,sys; print(json.load(sys.stdin)[0]['n'])")
test "$N" -gt 0

step "passed: the installed wheel works outside the checkout"
