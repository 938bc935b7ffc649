"""`python -m suds_exp`: the same command-line app as `suds-exp`.

The app is cli.py at the top of the repository (the installed module ``cli``). This
module is an entry point, not part of the library: nothing in suds_exp imports it, and
it is the one module allowed to import cli (pyproject.toml, [tool.importlinter]).
"""

from cli import app

if __name__ == "__main__":
    app(prog_name="suds-exp")
