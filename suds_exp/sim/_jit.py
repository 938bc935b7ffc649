"""numba for the simulator, its on-disk cache keyed on every source file of `suds_exp.sim`.

numba keys a function cached with ``cache=True`` on its own file's contents only. A
kernel that calls an njit function of another module compiles that function's code into
its own, and reads module constants (the packed parameters' indices, which
`sim/effect_params.py` lays out) as literals, so after that other module changed numba
would load the kernel's stale machine code. Here a function defined in a file of a
registered source tree (`cache_by_tree`; the simulator's own folder is registered on
import) is stamped with the hash of all the tree's ``.py`` files instead of its own
file's: any change to the simulator recompiles all its kernels, once, on first use (some
15 CPU seconds, `suds_exp.sim.precompile`). The cache stays where numba puts it
(``__pycache__``, or ``NUMBA_CACHE_DIR``). Import `njit` and `prange` from here, so the
locator is in place before a kernel is declared.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

from numba import njit, prange
from numba.core import caching

__all__ = ["cache_by_tree", "njit", "prange", "tree_stamp"]

_TREES: set[Path] = set()
_STAMPS: dict[Path, str] = {}


def tree_stamp(root: str | Path) -> str:
    """SHA-256 (hex) of the names and contents of every ``.py`` file under `root`."""
    h = hashlib.sha256()
    root = Path(root)
    for path in sorted(root.rglob("*.py")):
        h.update(path.relative_to(root).as_posix().encode() + b"\0")
        h.update(path.read_bytes() + b"\0")
    return h.hexdigest()


class _TreeLocator(caching._CacheLocator):
    """numba's usual locator for a function (cache folder, name), with the stamp of the
    whole source tree the function's file belongs to."""

    _fallbacks: tuple = ()

    def __init__(self, inner: caching._CacheLocator, root: Path):
        self._inner = inner
        self._root = root

    def ensure_cache_path(self):
        self._inner.ensure_cache_path()

    def get_cache_path(self):
        return self._inner.get_cache_path()

    def get_source_stamp(self):
        if self._root not in _STAMPS:
            _STAMPS[self._root] = tree_stamp(self._root)
        return _STAMPS[self._root]

    def get_disambiguator(self):
        return self._inner.get_disambiguator()

    @classmethod
    def from_function(cls, py_func, py_file):
        path = Path(py_file).resolve()
        root = next((r for r in _TREES if path.is_relative_to(r)), None)
        if root is None:
            return None
        for fallback in cls._fallbacks:
            inner = fallback.from_function(py_func, py_file)
            if inner is not None:
                return cls(inner, root)
        return None


def cache_by_tree(root: str | Path) -> None:
    """Stamp numba's cache of every function defined under `root` with `tree_stamp(root)`
    (for functions declared after this call)."""
    locators = caching.CacheImpl._locator_classes
    if _TreeLocator not in locators:
        _TreeLocator._fallbacks = tuple(locators)
        locators.insert(0, _TreeLocator)
    _TREES.add(Path(root).resolve())


cache_by_tree(Path(__file__).parent)
