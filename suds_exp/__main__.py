"""`python -m suds_exp`: the same command-line app as `suds-exp`.

The app is cli.py at the top of the repository; an installed wheel holds it as
``suds_exp.app.cli`` (pyproject.toml maps it there), a checkout has it as the module
``cli``. This module is an entry point, not part of the library: nothing in suds_exp
imports it, and it is the one module allowed to import cli (pyproject.toml,
[tool.importlinter]).
"""

import importlib
from pathlib import Path


def _app():
    # a checkout (cli.py and pyproject.toml beside the package) runs its own cli.py; an
    # installed wheel its suds_exp.app.cli. By name, since suds_exp.app exists only in a
    # wheel, never in the source tree
    top = Path(__file__).resolve().parents[1]
    if (top / "cli.py").is_file() and (top / "pyproject.toml").is_file():
        return importlib.import_module("cli").app
    return importlib.import_module("suds_exp.app.cli").app


app = _app()

if __name__ == "__main__":
    app(prog_name="suds-exp")
