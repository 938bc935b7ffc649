"""MkDocs hook: the reference pages that are generated from the code at build time.

A page asks for a generated section with a marker line of its own, e.g.
``<!-- generated: database -->``; this hook replaces it with Markdown made from the code,
so the reference cannot drift from what the package does:

- ``database``: every table and view, from a scratch database migrated by the package's
  own migration runner (the live schema), with the comment above each ``CREATE`` in
  ``migrations/*.sql`` and the migration that created it;
- ``preprocessing-parameters``: `suds_exp.preprocess.params.DEFAULTS` with the comments
  written beside each entry in ``params.py``, and the presets;
- ``simulator-effects``: `suds_exp.sim.effect_library()`;
- ``cli``: every command of the typer app ``cli:app``, by typer's own documentation
  generator (``typer cli utils docs``), the same text ``--help`` prints.

It also renders display math, ``$$ TeX $$``, to inline SVG with matplotlib's mathtext
at build time, so equations show on a site opened from files, with no script and no
network (a MathJax page needs both).
"""

from __future__ import annotations

import html
import re
import sys
import tempfile
import textwrap
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
MARKER = re.compile(r"^<!-- generated: ([a-z-]+) -->$", re.MULTILINE)


def on_config(config):
    # column_notes.py, beside this file, is imported by the database generator
    if str(HERE) not in sys.path:
        sys.path.insert(0, str(HERE))
    return config


def on_page_markdown(markdown, page, config, files):
    def render(match: re.Match) -> str:
        name = match.group(1)
        if name not in GENERATORS:
            raise KeyError(f"{page.file.src_path}: no generator named {name!r}")
        return GENERATORS[name]()

    return DISPLAY_MATH.sub(math_image, MARKER.sub(render, markdown))


# --- math ------------------------------------------------------------------------------

DISPLAY_MATH = re.compile(r"\$\$(.+?)\$\$", re.DOTALL)


def math_image(match: re.Match) -> str:
    """``$$ TeX $$`` as an ``<img>`` of its SVG (matplotlib mathtext: sums, sub- and
    superscripts, accents and spacing; TeX beyond that fails the build, by design)."""
    import base64
    import html
    import io

    import matplotlib

    matplotlib.use("Agg")
    from matplotlib import mathtext

    tex = " ".join(match.group(1).split())
    buf = io.BytesIO()
    with matplotlib.rc_context({"svg.hashsalt": "suds-docs", "svg.fonttype": "path"}):
        mathtext.math_to_image(f"${tex}$", buf, format="svg", dpi=110)
    data = base64.b64encode(buf.getvalue()).decode()
    return f'<img class="math" alt="{html.escape(tex)}" src="data:image/svg+xml;base64,{data}">'


# --- database --------------------------------------------------------------------------

_CREATE = re.compile(
    r"((?:^--[^\n]*\n)*)^CREATE\s+(TABLE|VIEW)\s+(\w+)", re.MULTILINE | re.IGNORECASE
)
_ALTER = re.compile(r"^ALTER\s+TABLE\s+(\w+)\s+ADD\s+COLUMN\s+(\w+)", re.MULTILINE | re.IGNORECASE)
_COLUMN_COMMENT = re.compile(r'^\s+"?(\w+)"?\s+[A-Z][^\n]*?--\s*(.+)$', re.MULTILINE)


def _migration_notes():
    """{object: (migration, comment above its CREATE)}, {(table, column): migration},
    {(table, column): the comment beside the column in its CREATE TABLE}."""
    created, added, comments = {}, {}, {}
    for path in sorted((ROOT / "migrations").glob("*.sql")):
        text = path.read_text()
        for match in _CREATE.finditer(text):
            comment, _kind, name = match.groups()
            lines = [ln[2:].strip() for ln in comment.strip().splitlines()]
            created[name] = (path.stem, " ".join(ln for ln in lines if ln))
            body = text[match.end() : text.find(";", match.end())]
            for column, note in _COLUMN_COMMENT.findall(body):
                comments[(name, column)] = note.strip()
        for table, column in _ALTER.findall(text):
            added[(table, column)] = path.stem
    return created, added, comments


def _live_schema():
    """Columns of every table and view of a database migrated by the package, as a frame."""
    from suds_exp.store import Store

    with tempfile.TemporaryDirectory() as tmp:
        store = Store(Path(tmp) / "schema.duckdb")
        store.upgrade()
        return store.query_df(
            "SELECT c.table_name, t.table_type, c.column_name, c.data_type, c.is_nullable "
            "FROM information_schema.columns c JOIN information_schema.tables t "
            "USING (table_schema, table_name) WHERE c.table_schema = 'main' "
            "ORDER BY t.table_type, c.table_name, c.ordinal_position"
        )


def database() -> str:
    from column_notes import COLUMN_NOTES

    created, added, comments = _migration_notes()
    schema = _live_schema()
    known = set(zip(schema.table_name, schema.column_name, strict=True))
    stale = sorted(set(COLUMN_NOTES) - known)
    if stale:
        raise RuntimeError(f"docs/hooks/column_notes.py: no such column(s) {stale}")
    out = []
    for kind, title in (("BASE TABLE", "Tables"), ("VIEW", "Views")):
        out.append(f"## {title}\n")
        for name, cols in schema[schema.table_type == kind].groupby("table_name", sort=False):
            migration, note = created.get(name, ("the migration runner", ""))
            out.append(f"### `{name}`\n")
            if note:
                out.append(f"{note}\n")
            out.append(f"Created by `{migration}`.\n")
            out.append("| column | type | null | meaning |")
            out.append("|---|---|---|---|")
            for col in cols.itertuples():
                key = (name, col.column_name)
                meaning = COLUMN_NOTES.get(key) or comments.get(key, "")
                if key in added:
                    meaning += f" (added by `{added[key]}`)"
                meaning = meaning.replace("|", "&#124;")
                out.append(
                    f"| `{col.column_name}` | {col.data_type} | {col.is_nullable.lower()} "
                    f"| {meaning} |"
                )
            out.append("")
    return "\n".join(out)


# --- preprocessing parameters ----------------------------------------------------------

_KEY = re.compile(r'^\s*"(\w+)":\s*(.+?),\s*(?:#\s*(.*))?$')
_COMMENT = re.compile(r"^\s*#\s?(.*)$")


def _is_heading(text: str) -> bool:
    # a section title in DEFAULTS ("# cleaning", "# phase (Phaser, ...)"): short, no ':' '='
    return ":" not in text and "=" not in text and len(text.split()) <= 6


def _parameter_comments() -> list[tuple[str, str, str]]:
    """(section, key, the comments written above and beside it in params.py)."""
    lines = (ROOT / "suds_exp" / "preprocess" / "params.py").read_text().splitlines()
    start = next(i for i, ln in enumerate(lines) if ln.startswith("DEFAULTS"))
    section, pending, rows = "", [], []
    for line in lines[start + 1 :]:
        if line.startswith("}"):
            break
        if m := _COMMENT.match(line):
            text = m.group(1).strip()
            if not pending and _is_heading(text):
                section = text
            else:
                pending.append(text)
        elif m := _KEY.match(line):
            rows.append((section, m.group(1), " ".join([*pending, m.group(3) or ""]).strip()))
            pending = []
    return rows


def preprocessing_parameters() -> str:
    from suds_exp.preprocess.params import DEFAULTS, PRESETS

    rows = _parameter_comments()
    missing = set(DEFAULTS) - {key for _, key, _ in rows}
    if missing:
        raise RuntimeError(f"params.py: could not read the comments of {sorted(missing)}")
    out, section, previous = [], None, ""
    for sec, key, text in rows:
        if sec != section:
            out += ["", f"## {sec[0].upper() + sec[1:]}", "", "| parameter | default | meaning |"]
            out.append("|---|---|---|")
            section = sec
        text = text or f"see `{previous}` above"
        out.append(f"| `{key}` | `{DEFAULTS[key]!r}` | {text.replace('|', '&#124;')} |")
        previous = key if not text.startswith("see ") else previous
    out += ["", "## Presets", "", "| preset | parameters over the defaults |", "|---|---|"]
    for name, over in PRESETS.items():
        shown = ", ".join(f"`{k}={v!r}`" for k, v in over.items()) or "(none: the defaults)"
        out.append(f"| `{name}` | {shown} |")
    return "\n".join(out) + "\n"


# --- simulator effects -----------------------------------------------------------------


def simulator_effects() -> str:
    from suds_exp.sim import effect_library

    out = []
    for eff in effect_library():
        out.append(f"### `{eff['name']}`\n")
        out.append(f"{eff['description']}\n")
        out.append(
            f"Main parameter `{eff['main']}`; nominal robot: {eff['nominal_state']}; "
            f"a replay of measured joint angles reproduces it: {eff['replay']}.\n"
        )
        out.append("| parameter | unit | nominal | realistic range | meaning |")
        out.append("|---|---|---|---|---|")
        for p in eff["parameters"]:
            lo, hi = p["range"]
            out.append(
                f"| `{p['config_key']}` | {p['unit']} | {p['nominal']} | {lo} - {hi} "
                f"| {p['description'].replace('|', '&#124;')} |"
            )
        out.append("")
    return "\n".join(out)


# --- command line ----------------------------------------------------------------------


def cli() -> str:
    """Typer's own Markdown for every command of ``cli:app``, headings one level down."""
    import typer.cli
    from typer.testing import CliRunner

    # `typer cli utils docs --name suds-exp`, run in this process
    # cli.py by its path: the repository's top is not on sys.path under mkdocs
    top = Path(__file__).resolve().parents[2]
    args = [str(top / "cli.py"), "utils", "docs", "--name", "suds-exp"]
    done = CliRunner().invoke(typer.cli.app, args)
    if done.exit_code != 0:
        raise RuntimeError(f"typer's docs generator failed:\n{done.output}")
    text = re.sub(r"^(#+) ", r"#\1 ", done.stdout, flags=re.MULTILINE)
    return re.sub(r"^Examples:\n((?:  .*\n)+)", _examples, text, flags=re.MULTILINE)


def _examples(match: re.Match) -> str:
    # a help's `Examples:` paragraph (one command a line, `\` continues one) as a console
    # block, as the help prints it, not as a Markdown paragraph that joins its lines
    lines = html.unescape(textwrap.dedent(match.group(1))).splitlines()
    shown = [line if line.startswith(" ") else f"$ {line}" for line in lines]
    return "**Examples**:\n\n```console\n" + "\n".join(shown) + "\n```\n"


GENERATORS = {
    "cli": cli,
    "database": database,
    "preprocessing-parameters": preprocessing_parameters,
    "simulator-effects": simulator_effects,
}
