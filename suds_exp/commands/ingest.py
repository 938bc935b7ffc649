"""`suds-exp ingest`: each file's outcome on the terminal, refusals in the CLI's words."""

from __future__ import annotations

import dataclasses
from pathlib import Path

from suds_exp import console
from suds_exp.commands.messages import user_message


def print_ingest(results: list, as_json: bool = False) -> int:
    """Print the outcome of each file of `ingest_paths` (``results``), or one JSON list;
    refusals go to stderr with parameters named by their flags. Returns how many files
    were refused."""
    results = [
        dataclasses.replace(r, message=user_message(r.error)) if r.error is not None else r
        for r in results
    ]
    failed = [r for r in results if r.status == "failed"]
    if as_json:
        console.print_json(
            [
                {"file": str(r.path), "status": r.status, "trial_id": r.trial_id}
                | ({"error": r.message} if r.status == "failed" else {})
                for r in results
            ]
        )
    else:
        for r in results:
            if r.status != "failed":
                console.out.print(f"{r.status} {r.message}")
    for r in failed:
        console.err.print(f"[red]error:[/red] {r.message}", markup=True, highlight=False)
    if failed and len(results) > 1:
        console.err.print(
            f"[red]error:[/red] {len(failed)} of {len(results)} files refused; "
            "the others are stored",
            markup=True,
            highlight=False,
        )
    return len(failed)


def print_trials(rows, as_json: bool = False, as_csv: bool = False) -> None:
    """The trials of `suds_exp.store.rows.trial_rows` as a table (file names without their
    folders), one JSON list or CSV (both with every column)."""
    from suds_exp.store.rows import Rows

    if as_json:
        console.print_json(rows)
        return
    if as_csv:
        console.print_csv(rows)
        return
    keep = [c for c in rows.columns if c not in ("id", "source_file", "ingested_at")]
    shown = Rows(
        ("id", "file", *keep),
        [
            (r["id"], Path(r["source_file"]).name, *(r[c] for c in keep))
            for r in (dict(zip(rows.columns, row, strict=True)) for row in rows.rows)
        ],
    )
    console.print_rows(shown, title="trials")
