"""Inference: posteriors of the strength and shot inputs given the measured features.

`settings` (the sampler's, the check's, the discrepancy's and a calibration's settings: the config's
`calibration` section), `problem` (the posterior density `Problem`: prior transform and batch log-likelihood
through the emulator), `sampler` (nested sampling with nautilus into a `Posterior`, with log Z and its sd),
`summaries` (weighted quantiles and their Monte Carlo errors), `calibration` (a study's shots
against its emulator), `coverage` (synthetic-truth checks), `inference_data` (a `Posterior` as
ArviZ InferenceData), `predict` (emulator predictions at a design),
`posterior_files` (a `Posterior` written and read back) and `study_results` (`load_study`: a finished
study's posteriors, emulator and measured features).
Hands on posteriors (draws, weighted draws, summaries, netCDF) to predictions, figures and the campaign.
"""

from shockcal._lazy import lazy_exports

__getattr__, __dir__, __all__ = lazy_exports(__name__, {
    "Problem": "shockcal.inference.problem",
    "SamplerSettings": "shockcal.inference.settings",
    "Posterior": "shockcal.inference.sampler",
    "sample": "shockcal.inference.sampler",
    "CalibrationSettings": "shockcal.inference.settings",
    "calibrate": "shockcal.inference.calibration",
    "read_posterior": "shockcal.inference.posterior_files",
    "load_study": "shockcal.inference.study_results",
    "StudyResults": "shockcal.inference.study_results",
})
