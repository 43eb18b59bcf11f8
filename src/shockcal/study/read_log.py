"""Which keys of its config slice a command reads: the check that a stage declares only what its job reads.

A stage's declared keys (`shockcal.study.stages`) are both the slice its command gets and its rule's `params`,
whose change reruns the job. A key declared but never read reruns jobs for nothing. With the environment variable
`SHOCKCAL_READ_LOG` naming a folder, each command's slice records the leaf keys its code reads (a value fetched by
key; every leaf of a section whose items or values are listed, copied, dumped or unpacked whole; the names of a
`{names}` section, listed or asked for), and the process writes one JSON file there at exit: the stage, the
declared leaf keys and the read ones (`tests/test_workflow.py` runs the quick study with it). Without the variable
nothing is wrapped.
"""

from __future__ import annotations

import atexit
import json
import os
from pathlib import Path

READ_LOG = "SHOCKCAL_READ_LOG"


class RecordingDict(dict):
    """A config slice (a dict, so every `isinstance(x, dict)` holds) that adds to `reads` the dotted path of each
    leaf its holder reads. Sub-sections come back wrapped; lists and scalars are leaves."""

    def __init__(self, data: dict, reads: set[str], prefix: str = ""):
        super().__init__(data)
        self._reads, self._prefix = reads, prefix

    def _path(self, key) -> str:
        return f"{self._prefix}{key}"

    def _wrap(self, key, value):
        if isinstance(value, dict):
            if not value:
                self._reads.add(self._path(key))
            if not isinstance(value, RecordingDict):   # wrapped once, in place: a change made to it stays
                value = RecordingDict(value, self._reads, f"{self._path(key)}.")
                dict.__setitem__(self, key, value)
            return value
        self._reads.add(self._path(key))
        return value

    def __getitem__(self, key):
        return self._wrap(key, super().__getitem__(key))

    def get(self, key, default=None):
        return self[key] if super().__contains__(key) else default

    def items(self):
        return [(key, self[key]) for key in self._names()]

    def values(self):
        return [self[key] for key in self._names()]

    def _names(self) -> list:
        """The keys, each empty section among them read: a `{names}` declaration is read by listing them."""
        names = list(dict.keys(self))
        self._reads.update(self._path(key) for key in names if dict.__getitem__(self, key) == {})
        return names

    def keys(self):
        return self._names()

    def __iter__(self):  # not the dict fast path: `{**d}`, `dict(d)` and `f(**d)` go through keys() and []
        return iter(self._names())

    def __contains__(self, key):
        if super().__contains__(key) and super().__getitem__(key) == {}:
            self._reads.add(self._path(key))
        return super().__contains__(key)

    def __deepcopy__(self, memo):
        return {key: _plain(value) for key, value in self.items()}


def _plain(value):
    """`value` with every leaf under it read (a deep copy's or a dump's view)."""
    return {key: _plain(item) for key, item in value.items()} if isinstance(value, dict) else value


def leaf_paths(config: dict, prefix: str = "") -> set[str]:
    """The dotted paths of every leaf of a nested dict."""
    paths: set[str] = set()
    for key, value in dict.items(config):
        path = f"{prefix}{key}"
        paths |= leaf_paths(value, f"{path}.") if isinstance(value, dict) and value else {path}
    return paths


def recorded(sliced: dict, stage: str) -> dict:
    """`sliced` as a `RecordingDict` logged at exit under `stage`, when `SHOCKCAL_READ_LOG` is set; else itself."""
    folder = os.environ.get(READ_LOG)
    if not folder:
        return sliced
    reads: set[str] = set()
    entry = {"stage": stage, "declared": sorted(leaf_paths(sliced)), "reads": reads}
    atexit.register(_write, Path(folder), entry)
    return RecordingDict(sliced, reads)


def _write(folder: Path, entry: dict) -> None:
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"{os.getpid()}-{entry['stage']}.json"
    path.write_text(json.dumps({**entry, "reads": sorted(entry["reads"])}))
