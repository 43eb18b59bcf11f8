"""Velocimetry: from a free-surface velocity trace to the calibration features.

Reads measured VISAR records (`records`) and estimates their noise (`record_noise`: AR(p) on the
plateau), fits the Gaussian mixture to a trace's exact piecewise-linear CDF (`mixture_fit`), and
extracts the paper's features (`features`: jump-off, elastic and plastic plateaus, the two slopes;
times in us, velocities in m/s). Hands on one features table per run set and shot, and the observed
features of the measured records with their read-out sd.
"""

from shockcal._lazy import lazy_exports

__getattr__, __dir__, __all__ = lazy_exports(__name__, {
    "ExtractorSettings": "shockcal.velocimetry.settings",
    "extract_features": "shockcal.velocimetry.features",
    "features_table": "shockcal.velocimetry.features",
    "record_features": "shockcal.velocimetry.features",
    "read_record": "shockcal.velocimetry.records",
    "estimate_noise": "shockcal.velocimetry.record_noise",
})
