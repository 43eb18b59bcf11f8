"""shockcal: Bayesian calibration of strength models from plate-impact velocimetry.

The array API for notebooks (README, "From a notebook"): `PCGPEmulator` and its `EmulatorSettings`
(fit, predict, cross-validate, save, load), `Problem` (a predictive model, measured features and a
prior box), `SamplerSettings` and `sample` (the posterior). Imported on first use, so the command
line starts without them.
"""

__version__ = "0.1.0"

_API = {"PCGPEmulator": ("shockcal.emulator", "PCGPEmulator"), "EmulatorSettings": ("shockcal.emulator", "Settings"),
        "Problem": ("shockcal.calibration", "Problem"), "SamplerSettings": ("shockcal.calibration", "SamplerSettings"),
        "sample": ("shockcal.calibration", "sample")}
__all__ = list(_API)


def __getattr__(name: str):
    if name not in _API:
        raise AttributeError(f"module 'shockcal' has no attribute {name!r}")
    import importlib

    module, attribute = _API[name]
    return getattr(importlib.import_module(module), attribute)
