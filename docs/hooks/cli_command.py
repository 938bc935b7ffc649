"""The `suds-exp` typer app as the click command mkdocs-click documents.

Typer builds a click group from the app; mkdocs-click walks that group, so every command,
argument and option in docs/reference/cli.md comes from `cli.app` itself (typer's own
`typer.main.get_command`), never written a second time.
"""

import typer

from cli import app

command = typer.main.get_command(app)
