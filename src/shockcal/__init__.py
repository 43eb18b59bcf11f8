"""shockcal: Bayesian calibration of strength models from plate-impact velocimetry."""

__version__ = "0.1.0"
