"""`python -m suds_exp` and the `suds-exp` script: the command-line app.

The app is cli.py at the top of the repository; an installed wheel holds it as
``suds_exp.app.cli`` (pyproject.toml maps it there), a checkout has it as the module
``cli``. This module is an entry point, not part of the library: nothing in suds_exp
imports it, and it is the one module allowed to import cli (pyproject.toml,
[tool.importlinter]).
"""

import importlib
import importlib.util
import sys
from pathlib import Path


def _app():
    # A checkout (cli.py and pyproject.toml beside the package, an editable install too)
    # runs its own cli.py, loaded from its file as the module `cli` (what the tests import):
    # the `suds-exp` script does not have the checkout on sys.path, and an editable
    # install cannot map the repository's top folder to a package. An installed wheel runs
    # its suds_exp.app.cli, by name, since suds_exp.app exists only in a wheel.
    top = Path(__file__).resolve().parents[1]
    if (top / "cli.py").is_file() and (top / "pyproject.toml").is_file():
        module = sys.modules.get("cli")
        if module is None:
            spec = importlib.util.spec_from_file_location("cli", top / "cli.py")
            module = importlib.util.module_from_spec(spec)
            sys.modules["cli"] = module
            spec.loader.exec_module(module)
        return module.app
    return importlib.import_module("suds_exp.app.cli").app


app = _app()

if __name__ == "__main__":
    app(prog_name="suds-exp")
