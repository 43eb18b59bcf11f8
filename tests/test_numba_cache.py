"""numba's cache keyed on every kernel file (shockcal._numba_cache): an edit of a callee's file reaches the
kernels that call it, which numba's own per-file key misses, and a user's NUMBA_CACHE_DIR is left alone."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from shockcal._numba_cache import DIGEST_VARIABLE, PACKAGE, kernel_digest, kernel_files, remove_stale_folders

CALLER = """
import numba

from toy.callee import value


@numba.njit(cache=True)
def twice():
    return 2 * value()
"""
CALLEE = """
import numba

from toy.constants import OFFSET


@numba.njit(cache=True)
def value():
    return {value} + OFFSET
"""
INIT = """
from pathlib import Path

from shockcal._numba_cache import use_kernel_keyed_cache

use_kernel_keyed_cache(Path(__file__).resolve().parent)
"""


def toy_package(root: Path, value: int, offset: int = 0) -> Path:
    """A package `toy` whose kernel `caller.twice` calls `callee.value`, which reads `constants.OFFSET`."""
    package = root / "toy"
    package.mkdir(exist_ok=True)
    (package / "__init__.py").write_text(INIT)
    (package / "caller.py").write_text(CALLER)
    (package / "callee.py").write_text(CALLEE.format(value=value))
    (package / "constants.py").write_text(f"OFFSET = {offset}\n")
    return package


def twice_in_a_new_process(root: Path, **env: str) -> int:
    """`toy.caller.twice()` in a fresh interpreter (numba's cache as that process finds it)."""
    clean = {k: v for k, v in os.environ.items() if k not in ("NUMBA_CACHE_DIR", DIGEST_VARIABLE)}
    done = subprocess.run([sys.executable, "-c", "from toy.caller import twice; print(twice())"], cwd=root,
                          env={**clean, "PYTHONPATH": str(root), **env}, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return int(done.stdout)


def test_an_edit_of_a_callee_or_a_constant_reaches_the_cached_caller(tmp_path):
    package = toy_package(tmp_path, value=1)
    assert twice_in_a_new_process(tmp_path) == 2
    assert list((package / "__pycache__").glob("numba-*/**/*.nbi")), "nothing was cached"
    old_folder = next((package / "__pycache__").glob("numba-*"))
    toy_package(tmp_path, value=5)                       # caller.py untouched: numba's own key would load 2
    # a child of a process started before the edit inherits its folder, and sets its own
    inherited = {"NUMBA_CACHE_DIR": str(old_folder), DIGEST_VARIABLE: old_folder.name.removeprefix("numba-")}
    assert twice_in_a_new_process(tmp_path, **inherited) == 10
    assert twice_in_a_new_process(tmp_path) == 10
    toy_package(tmp_path, value=5, offset=1)            # a constant in a module without numba
    assert twice_in_a_new_process(tmp_path) == 12


def test_numbas_own_key_misses_the_callee_edit_so_the_test_above_can_fail(tmp_path):
    """With the user's NUMBA_CACHE_DIR (left alone), numba's per-file key loads the stale caller."""
    user_cache = str(tmp_path / "user-cache")
    toy_package(tmp_path, value=1)
    assert twice_in_a_new_process(tmp_path, NUMBA_CACHE_DIR=user_cache) == 2
    toy_package(tmp_path, value=5)
    assert twice_in_a_new_process(tmp_path, NUMBA_CACHE_DIR=user_cache) == 2
    # the user's folder in a child of a shockcal process (the digest variable inherited) is still the user's
    assert twice_in_a_new_process(tmp_path, NUMBA_CACHE_DIR=user_cache, **{DIGEST_VARIABLE: "0" * 12}) == 2
    assert not list((tmp_path / "toy" / "__pycache__").glob("numba-*"))


def test_the_digest_covers_the_kernels_and_what_they_import():
    names = {path.relative_to(PACKAGE).as_posix() for path in kernel_files()}
    assert {"hydro/solver.py", "hydro/plastic_return.py", "hydro/laws/preston_tonks_wallace.py",
            "hydro/state.py", "units.py", "velocimetry/mixture_fit.py"} <= names
    assert "cli/main.py" not in names and "study/figure_catalogue.py" not in names
    assert len(kernel_digest()) == 12 and kernel_digest() == kernel_digest()


def test_stale_folders_beyond_the_most_recent_are_removed(tmp_path):
    folders = [tmp_path / f"numba-{k:012d}" for k in range(7)]
    for age, folder in enumerate(folders):
        folder.mkdir()
        os.utime(folder, (1e9 + age, 1e9 + age))
    remove_stale_folders(tmp_path, current=folders[0], kept=4)
    assert sorted(path.name for path in tmp_path.iterdir()) == [f.name for f in [folders[0], *folders[3:]]]


def test_the_package_points_numba_at_its_digest_folder():
    """Importing shockcal (this process did) set numba's cache to this tree's digest folder."""
    if DIGEST_VARIABLE not in os.environ:
        pytest.skip("NUMBA_CACHE_DIR was set before shockcal was imported: the user's cache, left alone")
    assert os.environ[DIGEST_VARIABLE] == kernel_digest()
    assert Path(os.environ["NUMBA_CACHE_DIR"]).name == f"numba-{kernel_digest()}"
    import numba.core.config

    assert numba.core.config.CACHE_DIR == os.environ["NUMBA_CACHE_DIR"]
