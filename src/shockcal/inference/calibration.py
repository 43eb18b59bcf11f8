"""Calibration of a study's shots: the measured features against the study's emulator, nested sampling,
the posterior with its summary (SPEC sections 5-6).

The density is `shockcal.inference.problem.Problem`, the sampler `shockcal.inference.sampler`, the summaries
`shockcal.inference.summaries`, the synthetic-truth checks `shockcal.inference.coverage`.
"""

from __future__ import annotations

import pandas as pd

from shockcal.inference.problem import LAMBDA_Y, Problem
from shockcal.inference.sampler import Posterior, sample
from shockcal.inference.settings import CalibrationSettings
from shockcal.inference.training_range import check_training_range
from shockcal.plausibility import check_observed_table, check_plateau


def calibrate(emulator, shots, observed: pd.DataFrame, settings: CalibrationSettings, source: str = "observed"
              ) -> Posterior:
    """Calibrate `shots` jointly (one shot = single-shot calibration).

    Args:
        emulator: the study's `Emulator`; its training runs' features (`training_features`) bound the
            measured ones (`settings.check_training_range`).
        shots: the shots calibrated together.
        observed: measured features, one row per shot (m/s and us).
        settings: sampler, observation sd, checks and units.
        source: names `observed` in errors.

    Returns:
        The `Posterior`; its `info` holds the shots, parameters, units and measured features too.
    """
    problem = Problem.for_shots(emulator, shots, observed, settings.sd_fraction, source, settings.bounds,
                                settings.units, settings.discrepancy)
    check_observed_table(observed, shots, source, settings.check_units)
    measured = {shot: dict(zip(emulator.feature_names, features))
                for shot, features in zip(shots, problem.observed.reshape(len(shots), -1))}
    for shot, features in measured.items():
        if shot in settings.velocity_boxes:
            check_plateau(features, settings.velocity_boxes[shot], f"{source}: shot {shot}", settings.check_plateau)
    if hasattr(emulator, "training_features"):     # the study's emulator; a stand-in without training runs is not checked
        check_training_range(measured, {shot: emulator.training_features(shot) for shot in shots}, source,
                             settings.check_training_range)
    posterior = sample(problem, settings.sampler, other_powers="ignore")
    units = {**{k: settings.units.get(k, "-") for k in problem.names}, LAMBDA_Y: "-",
             **{k: "-" for k in problem.discrepancy_names}}
    posterior.units = units
    posterior.user_units = {k: settings.user_units.get(k, unit) for k, unit in units.items()}
    posterior.context.update(shots=list(shots), parameters=problem.names, units=units, user_units=posterior.user_units,
                             observed=problem.observed.tolist(), observed_sd_m_s=problem.obs_sd.tolist())
    if problem.discrepancy is not None:    # absent without one: the files of `discrepancy: none` are as before
        posterior.context.update(discrepancy_parameters=problem.discrepancy_names,
                                 discrepancy_sd_fraction_prior=problem.discrepancy.sd_fraction_prior)
    return posterior
