"""`suds-exp preprocess`: its options from their strings, the versions table, the line it
prints."""

from __future__ import annotations

from collections.abc import Iterable, Sequence

from suds_exp import console
from suds_exp.errors import ConfigError
from suds_exp.preprocess import list_versions
from suds_exp.preprocess import preprocess as run_preprocess
from suds_exp.robot import parse_ids


def preprocess_command(
    store,
    name: str | None = None,
    params: Sequence[str] = (),
    trials: str | None = None,
    body: str | None = None,
    preset: str | None = None,
    progress: bool = False,
):
    """`preprocess` (or, with ``body``, a TOML file or built-in name, `preprocess_body`)
    from the command's strings: ``params`` as ``KEY=VALUE`` items, ``trials`` as ids text."""
    common = dict(
        params=parse_param_items(list(params)),
        trials=parse_ids(trials),
        progress=progress,
        preset=preset,
    )
    if body is not None:
        from suds_exp.body import load_body, preprocess_body

        return preprocess_body(store, load_body(body), name, **common)
    return run_preprocess(store, name, **common)


def print_versions(store, as_json: bool = False, as_csv: bool = False) -> None:
    """The stored preprocessing versions, as a table, one JSON list or CSV (every column,
    ``params`` as its JSON text)."""
    frame = list_versions(store)
    if as_json:
        console.print_json(frame)
    elif as_csv:
        console.print_csv(frame.assign(params=frame.params.map(_json_text)))
    else:
        shown = frame.drop(columns=["params"]).assign(params_hash=frame.params_hash.str[:12])
        console.print_frame(shown, title="preprocessing versions")


def preprocess_text(result) -> str:
    """The one line `suds-exp preprocess` prints for a preprocessing result."""
    ev = ", ".join(f"{100 * r:.1f}%" for r in result.explained_variance_ratio)
    return (
        f"version {result.version_id} ({result.name}, params {result.params_hash[:12]}): "
        f"{'created' if result.created else 'reused'}; processed {len(result.processed)} "
        f"trials ({result.n_samples} samples), skipped {len(result.skipped)} already done, "
        f"in {result.seconds:.1f} s; "
        f"{explained_label(result.params)} explain {ev}"
        + (
            f"; {result.interpolated_pose_frames} segment poses interpolated (too few markers seen)"
            if result.interpolated_pose_frames
            else ""
        )
    )


def explained_label(params: dict) -> str:
    """What a preprocessing result's explained_variance_ratio describes."""
    if "body" in params:
        return "shape modes"
    return {
        "kernel-pca": "kernel PCs (feature-space variance)",
        "autoencoder": "autoencoder coordinates (reconstruction)",
    }.get(params.get("reduction", "pca"), "passive PCs")


def parse_param_items(items: Iterable[str]) -> dict[str, str]:
    """``["k=3", "jump_mm=12"]`` -> ``{"k": "3", "jump_mm": "12"}`` (values still text)."""
    out: dict[str, str] = {}
    for item in items:
        key, sep, value = item.partition("=")
        key, value = key.strip(), value.strip()
        if not sep or not key or not value:
            raise ConfigError(
                f"params {item!r}: expected KEY=VALUE, e.g. params k=3", param="params"
            )
        if key in out:
            raise ConfigError(f"params {key}: given twice", param="params")
        out[key] = value
    return out


def _json_text(params) -> str:
    import json

    return params if isinstance(params, str) else json.dumps(params, sort_keys=True)
