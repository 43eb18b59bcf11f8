"""numba's on-disk cache, keyed on every kernel file of the package.

numba keys a cached kernel on the file that defines it (that file's modification time and size), not on
the files of the kernels it calls: after an edit of `hydro/plastic_return.py` or a strength law (or a
`git pull` that changes them), `hydro/solver.simulate` would load machine code compiled from the old
callee. shockcal therefore points numba's cache (`NUMBA_CACHE_DIR`) at a folder named by a digest of
every package file that imports numba and of the package modules those import (`kernel_files`): any
change to them compiles afresh, an unchanged tree loads what it compiled. The folder is
`__pycache__/numba-<digest>` inside the package (`~/.cache/shockcal/` when the package is read-only);
the most recent `KEPT_STALE_FOLDERS` others are kept, older ones removed.

A `NUMBA_CACHE_DIR` the user set is left alone. The one shockcal sets is named by the digest it exports in
`DIGEST_VARIABLE`, so a process started from an older tree (a job of a snakemake started before an edit) sets
its own.
"""

from __future__ import annotations

import hashlib
import os
import re
import shutil
import sys
import tempfile
import warnings
from pathlib import Path

PACKAGE = Path(__file__).resolve().parent
FOLDER_PREFIX = "numba-"
DIGEST_VARIABLE = "SHOCKCAL_KERNEL_DIGEST"
KEPT_STALE_FOLDERS = 4
USES_NUMBA = re.compile(rb"^\s*(?:import|from) numba\b", re.MULTILINE)


def module_file(name: str, package: Path = PACKAGE) -> Path:
    """The file of module `name` (dotted, under `package`'s parent): `a/b.py`, or `a/b/__init__.py`."""
    base = package.parent.joinpath(*name.split("."))
    return base.with_suffix(".py") if base.with_suffix(".py").is_file() else base / "__init__.py"


def kernel_files(package: Path = PACKAGE) -> list[Path]:
    """The package's files that import numba and, transitively, the package modules they import: the code a
    compiled kernel can hold (its callees, and the constants and tuple types it reads). Sorted by path."""
    imports = re.compile(rb"^\s*(?:import|from) (%s(?:\.\w+)*)" % re.escape(package.name.encode()), re.MULTILINE)
    found: set[Path] = set()
    pending = [path for path in package.rglob("*.py") if USES_NUMBA.search(path.read_bytes())]
    while pending:
        path = pending.pop()
        if path in found or not path.is_file():
            continue
        found.add(path)
        pending += [module_file(name.decode(), package) for name in imports.findall(path.read_bytes())]
    return sorted(found)


def kernel_digest(package: Path = PACKAGE) -> str:
    """12 hex digits of a sha256 over the kernel files' paths (relative to `package`) and contents."""
    digest = hashlib.sha256()
    for path in kernel_files(package):
        digest.update(path.relative_to(package).as_posix().encode() + b"\0" + path.read_bytes() + b"\0")
    return digest.hexdigest()[:12]


def writable_root(package: Path = PACKAGE) -> Path | None:
    """Where the digest folders live: the package's __pycache__, else ~/.cache/shockcal (a read-only install);
    the first one that can be created and written, or None."""
    for root in (package / "__pycache__", Path.home() / ".cache" / "shockcal"):
        try:
            root.mkdir(parents=True, exist_ok=True)
            tempfile.TemporaryFile(dir=root).close()
            return root
        except OSError:
            continue
    return None


def remove_stale_folders(root: Path, current: Path, kept: int = KEPT_STALE_FOLDERS) -> None:
    """Remove the digest folders under `root` other than `current`, but the `kept` most recently modified."""
    others = [path for path in root.glob(f"{FOLDER_PREFIX}*") if path.is_dir() and path != current]
    for path in sorted(others, key=lambda p: p.stat().st_mtime, reverse=True)[kept:]:
        shutil.rmtree(path, ignore_errors=True)


def use_kernel_keyed_cache(package: Path = PACKAGE) -> Path | None:
    """Point numba's cache at this tree's digest folder (module docstring) and return it; None when the user
    set NUMBA_CACHE_DIR, or when no folder can be written (numba's own per-file key then, with a warning).
    Call before any kernel module is imported (shockcal's __init__ does). Imported after numba, it makes numba
    re-read its NUMBA_* variables, so numba settings made in code before that are lost: import shockcal first."""
    current = os.environ.get("NUMBA_CACHE_DIR")
    if current is not None and Path(current).name != FOLDER_PREFIX + os.environ.get(DIGEST_VARIABLE, ""):
        return None                                         # the user's cache
    digest = kernel_digest(package)
    root = writable_root(package)
    if root is None:
        warnings.warn("shockcal: no writable folder for numba's cache keyed on the kernel files; numba keys each "
                      "kernel on its own file, so after an edit of a callee delete the cached kernels", stacklevel=2)
        return None
    folder = root / f"{FOLDER_PREFIX}{digest}"
    if current != str(folder):
        os.environ["NUMBA_CACHE_DIR"] = str(folder)
        os.environ[DIGEST_VARIABLE] = digest
        remove_stale_folders(root, folder)
        if "numba.core.config" in sys.modules:            # numba read its settings before shockcal was imported
            sys.modules["numba.core.config"].reload_config()
    return folder
