"""Strength laws compared by their evidence: one row per law from its joint posterior and its emulator's
held-out errors. The table's columns:

    model, n_params, log_z, log_z_sd, log_bf_vs_johnson_cook, log_bf_sd, n_box_params, log_z_box_half,
    log_z_box_half_sd, log_z_box_double, posterior_mass_near_faces, kfold_rmse_m_s, outer_rmse_m_s

log_bf_vs_johnson_cook = log Z - log Z(johnson-cook), its sd the two sds in quadrature (independent
runs). log_z_sd is nautilus's importance-sampling estimate (`Posterior.log_evidence_sd`), a lower bound
of the Monte Carlo spread. The box columns (`shockcal.campaign.box_sensitivity`): the evidence with the box of the
law's own and shear-modulus parameters halved (exact, with its sd) and doubled (a lower bound) about its
centre, from the same run's weighted draws, and the posterior mass near the faces the doubled box moves.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import NamedTuple

import pandas as pd

from shockcal.campaign.box_sensitivity import BoxSensitivity
from shockcal.errors import InputError

REFERENCE_MODEL = "johnson-cook"
COLUMNS = ["model", "n_params", "log_z", "log_z_sd", "log_bf_vs_johnson_cook", "log_bf_sd", "n_box_params",
           "log_z_box_half", "log_z_box_half_sd", "log_z_box_double", "posterior_mass_near_faces", "kfold_rmse_m_s",
           "outer_rmse_m_s", "heldout_rmse_m_s", "heldout_coverage"]


class ModelResult(NamedTuple):
    """One law's study: its joint posterior's calibrated inputs, log evidence and sd, the measured
    features it was calibrated on (m/s), its emulator's K-fold and outer-check RMSE over all shots
    and features (m/s), the evidence's sensitivity to its box, and its emulator's RMSE (m/s) and 90%
    band coverage on the posterior's predictive runs, which no fit saw (NaN without them)."""

    parameters: tuple[str, ...]
    log_z: float
    log_z_sd: float
    observed_m_s: tuple[float, ...]
    kfold_rmse_m_s: float
    outer_rmse_m_s: float
    box: BoxSensitivity
    heldout_rmse_m_s: float = math.nan
    heldout_coverage: float = math.nan


def evidence_table(results: Mapping[str, ModelResult]) -> pd.DataFrame:
    """The comparison table (COLUMNS), one row per law in the given order. InputError when Johnson-Cook is
    missing, or a law was calibrated on other measured features than Johnson-Cook (evidences of different
    data do not compare)."""
    if REFERENCE_MODEL not in results:
        raise InputError(f"compare-models: no {REFERENCE_MODEL} study given; the Bayes factors are against it")
    reference = results[REFERENCE_MODEL]
    rows = []
    for model, result in results.items():
        if len(result.observed_m_s) != len(reference.observed_m_s) or any(
                not math.isclose(a, b, rel_tol=1e-12) for a, b in zip(result.observed_m_s, reference.observed_m_s)):
            raise InputError(f"compare-models: {model} was calibrated on other measured features than "
                             f"{REFERENCE_MODEL}; its evidence does not compare")
        rows.append({"model": model, "n_params": len(result.parameters), "log_z": result.log_z,
                     "log_z_sd": result.log_z_sd, "log_bf_vs_johnson_cook": result.log_z - reference.log_z,
                     "log_bf_sd": 0.0 if model == REFERENCE_MODEL else math.hypot(result.log_z_sd, reference.log_z_sd),
                     "n_box_params": result.box.k, "log_z_box_half": result.box.log_z_half,
                     "log_z_box_half_sd": result.box.log_z_half_sd, "log_z_box_double": result.box.log_z_double,
                     "posterior_mass_near_faces": result.box.mass_near_faces,
                     "kfold_rmse_m_s": result.kfold_rmse_m_s, "outer_rmse_m_s": result.outer_rmse_m_s,
                     "heldout_rmse_m_s": result.heldout_rmse_m_s, "heldout_coverage": result.heldout_coverage})
    return pd.DataFrame(rows, columns=COLUMNS)
