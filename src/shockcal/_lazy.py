"""Lazy public names of a package: `from shockcal.emulator import PCGPEmulator` works and tab completion lists
the names, yet importing the package loads none of its modules (the command line starts without numba kernels
or scikit-learn it does not use)."""

from __future__ import annotations

import importlib


def lazy_exports(package: str, names: dict[str, str]):
    """The `__getattr__`, `__dir__` and `__all__` of `package` (PEP 562) for `names`: public name -> the module
    that defines it (a dotted path; `module:attribute` when the attribute has another name there)."""

    def __getattr__(name: str):
        if name not in names:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        module, _, attribute = names[name].partition(":")
        return getattr(importlib.import_module(module), attribute or name)

    def __dir__() -> list[str]:
        return sorted(set(names) | {"__doc__", "__name__", "__path__"})

    return __getattr__, __dir__, sorted(names)
