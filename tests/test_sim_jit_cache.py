"""numba's on-disk cache of the simulator follows a change to any of its modules.

numba stamps a cached function with its own file only, so a kernel calling an njit
function of another module would keep that function's old code after the other module
changed. `suds_exp.sim._jit` stamps every function of a registered source tree (the
simulator's folder) with the hash of the whole tree. Checked here on a two-module
package run in fresh processes, as a user's next run would be.
"""

from __future__ import annotations

import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from suds_exp.sim import _jit, rft

KERNEL = """
from numba import njit
from toypkg.helper import value

@njit(cache=True)
def run():
    return value() + 0
"""


def _run(tmp_path: Path, by_tree: bool) -> int:
    """The kernel's result in a fresh interpreter (its machine code from the cache if fresh)."""
    register = f"cache_by_tree({str(tmp_path / 'toypkg')!r})" if by_tree else ""
    script = textwrap.dedent(
        f"""
        import sys
        sys.path.insert(0, {str(tmp_path)!r})
        from suds_exp.sim._jit import cache_by_tree
        {register}
        from toypkg.kernel import run
        print(run())
        """
    )
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=True)
    return int(out.stdout.strip())


def _package(tmp_path: Path, helper_value: int) -> None:
    pkg = tmp_path / "toypkg"
    pkg.mkdir(exist_ok=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "kernel.py").write_text(KERNEL)
    (pkg / "helper.py").write_text(
        f"from numba import njit\n\n@njit(cache=True)\ndef value():\n    return {helper_value}\n"
    )


@pytest.mark.parametrize("by_tree", [False, True])
def test_a_changed_helper_module_recompiles_the_kernel_calling_it(tmp_path, by_tree):
    _package(tmp_path, 1)
    assert _run(tmp_path, by_tree) == 1
    assert _run(tmp_path, by_tree) == 1  # loaded from the cache
    _package(tmp_path, 2)
    # numba alone keeps the kernel's stale copy of the helper; stamped by the tree, it
    # recompiles
    assert _run(tmp_path, by_tree) == (2 if by_tree else 1)


def test_the_simulator_kernels_are_stamped_by_all_its_sources():
    sim = Path(rft.__file__).parent
    stamp = rft.run_trials._cache._cache_file._source_stamp
    assert stamp == _jit.tree_stamp(sim)
