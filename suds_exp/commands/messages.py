"""A library error in the command line's words: parameters become flags, steps commands.

The library names Python parameters (``max_effects``) and advises steps in words ("ingest
some first", ``step="ingest"``); this is the one place that knows the flag of each
parameter and the command of each step.
"""

from __future__ import annotations

import re

from suds_exp.errors import SudsError

#: Library parameters whose flag is not simply ``--`` + the name with dashes (in every
#: command; a command adds its own with ``@command(flags=...)`` in cli.py).
FLAGS: dict[str, str] = {
    "effects": "--effect",
    "params": "--param",
    "model_params": "--model-param",
}

#: The command that takes each library step an error may advise (`SudsError.step`).
COMMANDS: dict[str, str] = {
    "init": "suds-exp init",
    "ingest": "suds-exp ingest",
    "trials": "suds-exp trials",
    "preprocess": "suds-exp preprocess",
    "run": "suds-exp run NAME",
    "stream": "suds-exp stream NAME",
}


def flag(param: str, flags: dict[str, str] | None = None) -> str:
    """The command-line flag of library parameter ``param`` (``max_effects`` ->
    ``--max-effects``), looked up in ``flags`` and then `FLAGS`."""
    return {**FLAGS, **(flags or {})}.get(param, "--" + param.replace("_", "-"))


def user_message(exc: SudsError, flags: dict[str, str] | None = None) -> str:
    """The error's one line in the CLI's words: each Python parameter name it is about
    (the error's ``param``, one name or several) becomes its flag where the text first
    names it as a word (later uses are ordinary words: "preset papers: unknown preset");
    the steps it advises (the error's ``step``) are followed by their commands."""
    text, params = str(exc), getattr(exc, "param", None)
    for param in _names(params):
        if param.startswith("-"):
            continue
        word = rf"(?<![\w.'\"=/\\-]){re.escape(param)}(?![\w'\"/\\-])"
        text = re.sub(word, flag(param, flags), text, count=1)
    commands = [f"`{COMMANDS[s]}`" for s in _names(getattr(exc, "step", None)) if s in COMMANDS]
    if commands:
        text += f" ({' or '.join(commands)})"
    return text


def _names(value: str | tuple[str, ...] | None) -> tuple[str, ...]:
    if not value:
        return ()
    return (value,) if isinstance(value, str) else tuple(value)
