"""shockcal: Bayesian calibration of strength models from plate-impact velocimetry.

The package is laid out as the method's stages, each a folder whose `__init__` says what it does and
what it hands on (docs/architecture.md): `hydro` (the 1D hydrocode) and `simulators` (the run
sources) -> `design` (which runs) -> `velocimetry` (records and features) -> `emulator` (PC-GP) ->
`inference` (posteriors) -> `campaign` (which law, which shot next); `study` reads the config,
`plots` draws the figures, `cli` holds the commands.

The array API for notebooks (README, "From a notebook"): `PCGPEmulator` and its `EmulatorSettings`
(fit, predict, cross-validate, save, load), `Problem` (a predictive model, measured features and a
prior box), `SamplerSettings` and `sample` (the posterior); `load_study(results_dir)`, a finished
study's posteriors (as `Posterior` and ArviZ InferenceData), emulator and measured features. Imported
on first use, so the command line starts without them.
"""

from shockcal._lazy import lazy_exports
from shockcal._numba_cache import use_kernel_keyed_cache

use_kernel_keyed_cache()    # before any kernel module: numba's cache keyed on every kernel file (_numba_cache)

__version__ = "0.1.0"

__getattr__, __dir__, __all__ = lazy_exports(__name__, {
    "PCGPEmulator": "shockcal.emulator.pcgp",
    "EmulatorSettings": "shockcal.emulator.settings",
    "Problem": "shockcal.inference.problem",
    "SamplerSettings": "shockcal.inference.settings",
    "sample": "shockcal.inference.sampler",
    "Posterior": "shockcal.inference.sampler",
    "load_study": "shockcal.inference.study_results",
})
