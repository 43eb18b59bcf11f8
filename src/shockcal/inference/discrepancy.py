"""The model-discrepancy term of a calibration (issue 63): delta ~ N(0, Sigma_delta), marginalised.

    y = eta(theta) + delta + e + eps,   delta ~ N(0, Sigma_delta(phi)),

Sigma_delta over the feature kinds (four per shot): feature i of kind k on shot s has sd
f_k |y_i| (f_k = `delta_sd_fraction_<kind>`, a fraction of the measured feature), two features of
the same kind on different shots correlate by rho (`delta_rho_shots`, one for all kinds), features
of different kinds are independent. It is a statement about the strength law's form: an error that
repeats across shots in proportion to each feature. It is not a per-shot free bias (confounded with
the per-shot impact velocity and moduli: Brynjarsdottir and O'Hagan 2014), and not a per-shot timing
shift. Priors: f_k half-normal with sd `sd_fraction_prior` (0.02: "a few %" of each feature, with
mass at 0 so that records without a discrepancy can shrink it), rho uniform on [0, 1].
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy import stats

from shockcal.errors import InputError
from shockcal.inference.settings import DiscrepancySettings

RHO_NAME = "delta_rho_shots"
SD_FRACTION_PREFIX = "delta_sd_fraction_"
SD_PREFIX = "delta_sd_"            # the implied sd in m/s: delta_sd_<feature>_m_s (`implied_sd_table`)


@dataclass(frozen=True)
class Discrepancy:
    """A feature-kind discrepancy over `feature_names` (the per-shot feature kinds, in order) for
    `n_shots` shots, shot-major like the observed vector; `sd_fraction_prior` the half-normal sd of
    each kind's fraction (dimensionless, > 0)."""

    feature_names: tuple[str, ...]
    n_shots: int
    sd_fraction_prior: float = DiscrepancySettings.model_fields["sd_fraction_prior"].default

    def __post_init__(self):
        DiscrepancySettings(kind="feature_kind", sd_fraction_prior=self.sd_fraction_prior)   # its limits, or a SettingsError

    @property
    def names(self) -> list[str]:
        """The sampled parameters' names: one sd fraction per feature kind, then rho."""
        return [f"{SD_FRACTION_PREFIX}{name}" for name in self.feature_names] + [RHO_NAME]

    def prior_transform(self, u: np.ndarray) -> np.ndarray:
        """Unit cube (N, kinds + 1) -> (fractions half-normal(0, sd_fraction_prior), rho uniform [0, 1])."""
        u = np.atleast_2d(u)
        fractions = self.sd_fraction_prior * stats.halfnorm.ppf(u[:, :-1])
        return np.column_stack([fractions, u[:, -1]])

    def covariance(self, phi: np.ndarray, observed: np.ndarray) -> np.ndarray:
        """Sigma_delta (N, F, F), (m/s)^2, at phi (N, kinds + 1) for the observed features (F,) m/s."""
        phi = np.atleast_2d(phi)
        k = len(self.feature_names)
        kind = np.tile(np.arange(k), self.n_shots)
        shot = np.repeat(np.arange(self.n_shots), k)
        same_kind = kind[:, None] == kind[None, :]
        same_shot = shot[:, None] == shot[None, :]
        sd = phi[:, kind] * np.abs(observed)[None, :]                      # (N, F)
        corr = np.where(same_kind & same_shot, 1.0, 0.0)[None] + \
            np.where(same_kind & ~same_shot, 1.0, 0.0)[None] * phi[:, -1, None, None]
        return sd[:, :, None] * corr * sd[:, None, :]


def from_setting(setting, feature_names, n_shots: int) -> Discrepancy | None:
    """The discrepancy a config's `calibration.discrepancy` asks for: "none" (or absent) -> None; a mapping
    {kind, sd_fraction_prior} or its `DiscrepancySettings`, checked by that model (a SettingsError naming the
    field); anything else is a one-line InputError."""
    if setting is None or setting == "none":
        return None
    if isinstance(setting, dict):
        setting = DiscrepancySettings(**setting)
    if not isinstance(setting, DiscrepancySettings):
        raise InputError(f"calibration.discrepancy = {setting!r}: give 'none' or {{kind: feature_kind, "
                         "sd_fraction_prior: 0.02}")
    if setting.kind == "none":
        return None
    return Discrepancy(tuple(feature_names), int(n_shots), setting.sd_fraction_prior)


def enabled(setting) -> bool:
    """Whether a `calibration.discrepancy` setting asks for a discrepancy (not none, absent or kind none)."""
    if isinstance(setting, dict):
        return setting.get("kind", "feature_kind") != "none"
    return setting not in (None, "none")


def is_discrepancy_parameter(name: str) -> bool:
    """Whether a posterior's parameter `name` is one of a discrepancy's (an sd fraction or rho)."""
    return name == RHO_NAME or name.startswith(SD_FRACTION_PREFIX)


def describe(name: str) -> str:
    """One line saying what a discrepancy parameter is, in user units (the InferenceData's `description`)."""
    if name == RHO_NAME:
        return ("model discrepancy: correlation (dimensionless, 0-1) between two shots' discrepancies of the same "
                "feature kind; prior uniform on [0, 1]")
    feature = name.removeprefix(SD_FRACTION_PREFIX)
    return (f"model discrepancy: its sd on {feature} as a fraction (dimensionless) of each shot's measured {feature}; "
            "prior half-normal with sd calibration.discrepancy.sd_fraction_prior; times the measured value: "
            f"{SD_PREFIX}{feature}_m_s")


def implied_sd_table(summary: pd.DataFrame, observed: pd.DataFrame) -> pd.DataFrame:
    """The discrepancy's sd in m/s per shot and feature at its posterior 5/50/95% points: the sd fraction's
    quantiles times the measured feature (a fraction of it, so the quantiles map exactly).

    Args:
        summary: a posterior summary (`Posterior.summary()`: `parameter`, `q05`, `q50`, `q95`); its
            `delta_sd_fraction_<feature>` rows are read.
        observed: measured features, m/s: one row per shot (index: shot), a column per feature.

    Returns:
        Rows (shot, feature): `observed_m_s`, `fraction_q05/q50/q95` (-), `sd_m_s_q05/q50/q95` (m/s);
        no rows when the summary has no sd fraction (`calibration.discrepancy: none`).
    """
    fractions = summary.set_index("parameter")
    rows = []
    for shot, measured in observed.iterrows():
        for feature, value in measured.items():
            name = f"{SD_FRACTION_PREFIX}{feature}"
            if name not in fractions.index:
                continue
            q = fractions.loc[name, ["q05", "q50", "q95"]].to_numpy(float)
            rows.append({"shot": str(shot), "feature": feature, "observed_m_s": float(value),
                         **{f"fraction_{k}": v for k, v in zip(("q05", "q50", "q95"), q)},
                         **{f"sd_m_s_{k}": v * abs(value) for k, v in zip(("q05", "q50", "q95"), q)}})
    return pd.DataFrame(rows, columns=["shot", "feature", "observed_m_s", "fraction_q05", "fraction_q50", "fraction_q95",
                                       "sd_m_s_q05", "sd_m_s_q50", "sd_m_s_q95"])
