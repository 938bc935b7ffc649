"""MkDocs hook: a page marked ``<!-- executed -->`` is run as a notebook at build time.

Its ```sh blocks (``suds-exp ...`` commands, run through typer's CliRunner) and ```python
blocks (one namespace for the page) run in order in a fresh folder; after a Python block
whose last statement is an expression, the page shows that value as a notebook would:
its ``_repr_html_()`` when it has one, else its ``repr`` in a code block. A command or a
block that fails fails the build, so the page always shows what the code does now. No
Jupyter is needed, and the page is plain Markdown that tests/test_docs.py runs too.
"""

from __future__ import annotations

import ast
import html
import os
import re
import shlex
import tempfile

MARK = "<!-- executed -->"
FENCE = re.compile(r"^```(?P<lang>sh|python)[^\n]*\n(?P<body>.*?)^```[ \t]*$", re.M | re.S)


def on_page_markdown(markdown, page, config, files):
    if MARK not in markdown:
        return markdown
    from typer.testing import CliRunner

    from suds_exp.__main__ import app  # the checkout's cli.py (not an importable module)

    runner = CliRunner()
    namespace: dict = {"__name__": "__docs__"}
    here = os.getcwd()
    out: list[str] = []
    last = 0
    with tempfile.TemporaryDirectory(prefix="suds-docs-") as folder:
        os.chdir(folder)
        try:
            for m in FENCE.finditer(markdown):
                out.append(markdown[last : m.end()])
                last = m.end()
                if m.group("lang") == "sh":
                    _run_shell(runner, app, m.group("body"), page)
                else:
                    shown = _run_python(m.group("body"), namespace, page)
                    if shown is not None:
                        out.append("\n\n" + _output(shown) + "\n")
        finally:
            os.chdir(here)
    out.append(markdown[last:])
    return "".join(out).replace(MARK, "")


def _run_shell(runner, app, code: str, page) -> None:
    for line in re.sub(r"\\\n\s*", " ", code).splitlines():
        argv = shlex.split(line, comments=True)
        if not argv:
            continue
        if argv[0] != "suds-exp":
            raise ValueError(f"{page.file.src_path}: cannot run {line!r}")
        done = runner.invoke(app, argv[1:], env=dict(os.environ))
        if done.exit_code != 0:
            raise RuntimeError(f"{page.file.src_path}: {line} failed:\n{done.output}")


def _run_python(code: str, namespace: dict, page):
    tree = ast.parse(code)
    tail = tree.body[-1] if tree.body and isinstance(tree.body[-1], ast.Expr) else None
    if tail is not None:
        tree.body.pop()
    exec(compile(tree, f"{page.file.src_path} (python block)", "exec"), namespace)
    if tail is None:
        return None
    return eval(compile(ast.Expression(tail.value), "<display>", "eval"), namespace)


def _output(value) -> str:
    if hasattr(value, "_repr_html_"):
        body = value._repr_html_()
    else:
        body = f"<pre><code>{html.escape(repr(value))}</code></pre>"
    # one line: Markdown passes a raw HTML block through only up to a blank line
    return '<div class="suds-output">' + " ".join(body.split("\n")) + "</div>"
