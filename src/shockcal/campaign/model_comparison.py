"""Strength laws compared by their evidence: one row per law from its joint posterior and its emulator's
held-out errors. The table's columns:

    model, n_params, log_z, log_z_sd, reference_model, log_bf_vs_reference, log_bf_sd, n_box_params,
    log_z_box_half, log_z_box_half_sd, log_z_box_double, posterior_mass_near_faces, kfold_rmse_m_s, outer_rmse_m_s,
    heldout_rmse_m_s, heldout_coverage

log_bf_vs_reference = log Z - log Z(reference_model), the reference the first law given unless named, its sd
the two sds in quadrature (independent runs; 0 on the reference's own row). log_z_sd is nautilus's
importance-sampling estimate (`Posterior.log_evidence_sd`), a lower bound of the Monte Carlo spread. The box
columns (`shockcal.campaign.box_sensitivity`): the evidence with the box of the law's own and shear-modulus
parameters halved (exact, with its sd) and doubled (a lower bound) about its centre, from the same run's
weighted draws, and the posterior mass near the faces the doubled box moves.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import NamedTuple

import pandas as pd

from shockcal.campaign.box_sensitivity import BoxSensitivity
from shockcal.errors import InputError

COLUMNS = ["model", "n_params", "log_z", "log_z_sd", "reference_model", "log_bf_vs_reference", "log_bf_sd", "n_box_params",
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


def evidence_table(results: Mapping[str, ModelResult], reference: str | None = None) -> pd.DataFrame:
    """The comparison table (COLUMNS), one row per law in the given order, the Bayes factors against `reference`
    (a law of `results`; None: the first). InputError when the reference is not among the laws, or a law was
    calibrated on other measured features than the reference (evidences of different data do not compare)."""
    reference = next(iter(results)) if reference is None else reference
    if reference not in results:
        raise InputError(f"compare-models: the reference law {reference} is not among the laws given "
                         f"({', '.join(results)}); the Bayes factors are against it")
    base = results[reference]
    rows = []
    for model, result in results.items():
        if len(result.observed_m_s) != len(base.observed_m_s) or any(
                not math.isclose(a, b, rel_tol=1e-12) for a, b in zip(result.observed_m_s, base.observed_m_s)):
            raise InputError(f"compare-models: {model} was calibrated on other measured features than "
                             f"{reference}; its evidence does not compare")
        rows.append({"model": model, "n_params": len(result.parameters), "log_z": result.log_z,
                     "log_z_sd": result.log_z_sd, "reference_model": reference,
                     "log_bf_vs_reference": result.log_z - base.log_z,
                     "log_bf_sd": 0.0 if model == reference else math.hypot(result.log_z_sd, base.log_z_sd),
                     "n_box_params": result.box.k, "log_z_box_half": result.box.log_z_half,
                     "log_z_box_half_sd": result.box.log_z_half_sd, "log_z_box_double": result.box.log_z_double,
                     "posterior_mass_near_faces": result.box.mass_near_faces,
                     "kfold_rmse_m_s": result.kfold_rmse_m_s, "outer_rmse_m_s": result.outer_rmse_m_s,
                     "heldout_rmse_m_s": result.heldout_rmse_m_s, "heldout_coverage": result.heldout_coverage})
    return pd.DataFrame(rows, columns=COLUMNS)
