"""`python -m suds_exp`: the same command-line app as `suds-exp`.

The app is cli.py at the top of the repository; an installed wheel holds it as
``suds_exp.app.cli`` (pyproject.toml maps it there), a checkout has it as the module
``cli``. This module is an entry point, not part of the library: nothing in suds_exp
imports it, and it is the one module allowed to import cli (pyproject.toml,
[tool.importlinter]).
"""

import importlib


def _app():
    # the installed name first: a user's own `cli.py` in the working folder is not ours.
    # By string, since suds_exp.app exists only in a wheel, never in the source tree
    try:
        return importlib.import_module("suds_exp.app.cli").app
    except ModuleNotFoundError:
        return importlib.import_module("cli").app


app = _app()

if __name__ == "__main__":
    app(prog_name="suds-exp")
