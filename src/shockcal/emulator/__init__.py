"""Emulator: the principal-component Gaussian-process emulator of the features.

`gp` (one GP at its MAP hyperparameters) on the correlation kernels of `correlation`; `pcgp` (the
array-level `PCGPEmulator` and its `EmulatorSettings`: fit, predict, K-fold, save, load) with its error model
(`error_model`: Student t or Gaussian) and the error's variance over the box (`variance_model`);
`study_emulator` maps a study's design columns and shots onto PC-GP blocks (`fit_emulator`,
`Emulator`); `heldout` scores one on runs it was not fitted on, feature by feature (`score_heldout`) and as the
vector the likelihood reads (`region_coverage`). Hands on a fitted
emulator (`emulator.npz` + `emulator.json`) to the inference.
"""

from shockcal._lazy import lazy_exports

__getattr__, __dir__, __all__ = lazy_exports(__name__, {
    "PCGPEmulator": "shockcal.emulator.pcgp",
    "EmulatorSettings": "shockcal.emulator.settings",
    "Emulator": "shockcal.emulator.study_emulator",
    "EmulatorSpec": "shockcal.emulator.study_emulator",
    "fit_emulator": "shockcal.emulator.study_emulator",
    "score_heldout": "shockcal.emulator.heldout",
    "region_coverage": "shockcal.emulator.heldout",
})
