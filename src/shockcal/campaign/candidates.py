"""Next-shot candidates (docs/next_shot.md): the joint posterior's draws as a candidate shot's
design, the check that the candidate's waves split, and the candidate's score from its runs' features.

A candidate's design holds one row per posterior draw: the draw's inputs (Table IV units; the same
rows for every candidate, so that candidates are compared on common draws), its `lambda_y`, two
nuisance inputs of the new shot, and the candidate's own velocity and shear modulus built from them:

    velocity_cm_us     = velocity_m_s * velocity_factor / 1e4,
                         velocity_factor uniform in 1 +- sqrt(3) f (sd f, the shot's velocity error);
    shear_modulus_Mbar = G_ref * (1 + s (T0 - T_ref)),
                         G_ref the draw's shear modulus of the reference shot, s (1/K) uniform in a range.

`Candidate.mapping()` reads these two columns, so the design runs through `simulate_design` as a
shot's does.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import numpy as np
import pandas as pd

from shockcal.campaign.settings import CandidateShot
from shockcal.design.posterior_draws import draw_posterior_design
from shockcal.design.tables import ShotMapping
from shockcal.errors import InputError
from shockcal.hydro import MaterialProperties
from shockcal.hydro.laws import DEFAULT_COLUMNS, DEFAULT_MODEL, get_law
from shockcal.hydro.settings_model import setting
from shockcal.inference.problem import LAMBDA_Y
from shockcal.units import CM_US_TO_M_S, PER_S_TO_PER_US

VELOCITY = "velocity_cm_us"
SHEAR_MODULUS = "shear_modulus_Mbar"
VELOCITY_FACTOR = "velocity_factor"
SLOPE = "shear_modulus_log_slope_per_K"
SPLIT_STRAIN_RATE_PER_S = 1.0e6   # the elastic front's strain rate for the HEL (the shots' peak rates: 0.7-3.4 /us)
SPLIT_SHARE = 0.5                 # the share of draws without an elastic-plastic split that stops a candidate


class Candidate(CandidateShot):
    """A candidate shot (`CandidateShot`: plates, initial temperature, None the material's T_ref_K, nominal impact
    velocity) with what the study gives it: the design inputs whose sum is its reference shot's shear modulus
    (Mbar), the study's strength law (`model`) and its design columns (`strength_inputs`,
    `shockcal.hydro.laws.Law.column`), which the posterior's draws give."""

    name: str = setting(..., "The candidate's name.")
    shear_modulus_inputs: tuple[str, ...] = setting(..., "The design inputs whose sum is its shear modulus (Mbar).")
    model: str = setting(DEFAULT_MODEL, "The study's strength law.")
    strength_inputs: tuple[str, ...] = setting(DEFAULT_COLUMNS, "The law's design columns.")

    def mapping(self) -> ShotMapping:
        """How the candidate reads its design (`candidate_design`'s velocity and shear-modulus columns)."""
        return ShotMapping(self.name, VELOCITY, (SHEAR_MODULUS,), self.model, self.strength_inputs)


def candidate_design(posterior: pd.DataFrame, names: Sequence[str], candidate: Candidate, n: int, seed: int,
                     material: MaterialProperties, velocity_sd_fraction: float,
                     slope_per_K: tuple[float, float], bounds: Mapping[str, tuple[float, float]] | None = None,
                     source: str = "posterior") -> pd.DataFrame:
    """`n` equal-weight posterior draws as `candidate`'s design (module docstring).

    Args:
        posterior: the joint posterior's equal-weight draws (inputs in Table IV units, `lambda_y` if sampled).
        names: the study's inputs (every one is kept, so theta is the whole joint posterior).
        candidate: the candidate shot.
        n: draws.
        seed: the draws' seed; the rows and the nuisance inputs depend on it alone, not on the candidate.
        material: the material (its T_ref_K).
        velocity_sd_fraction: the new shot's impact-velocity error, a fraction (sd).
        slope_per_K: (min, max) of d ln G / dT (1/K) for a hot candidate.
        bounds: the prior box by input: every draw must lie in it.
        source: names `posterior` in errors.

    Returns `run`, the inputs, `lambda_y` (1 when the posterior has none), VELOCITY_FACTOR, SLOPE,
    VELOCITY (cm/us) and SHEAR_MODULUS (Mbar).
    """
    columns = [*names, *([LAMBDA_Y] if LAMBDA_Y in posterior.columns else [])]
    design = draw_posterior_design(posterior, columns, n, seed, source, bounds)
    if LAMBDA_Y not in design.columns:
        design[LAMBDA_Y] = 1.0
    nuisance = np.random.default_rng(np.random.SeedSequence(seed).spawn(1)[0]).uniform(size=(2, n))
    design[VELOCITY_FACTOR] = 1.0 + math.sqrt(3.0) * velocity_sd_fraction * (2.0 * nuisance[0] - 1.0)
    design[SLOPE] = slope_per_K[0] + (slope_per_K[1] - slope_per_K[0]) * nuisance[1]
    heating = 0.0 if candidate.initial_temperature_K is None else candidate.initial_temperature_K - material.T_ref_K
    design[VELOCITY] = candidate.velocity_m_s / CM_US_TO_M_S * design[VELOCITY_FACTOR]
    g_ref = design[list(candidate.shear_modulus_inputs)].sum(axis=1)
    design[SHEAR_MODULUS] = g_ref if heating == 0.0 else g_ref * (1.0 + design[SLOPE] * heating)
    return design


def hel_particle_velocity_m_s(design: pd.DataFrame, candidate: Candidate, material: MaterialProperties) -> np.ndarray:
    """Particle velocity (m/s) behind each draw's elastic precursor in the candidate's plates: the
    uniaxial-strain yield sigma_HEL = Y0 (K + 4G/3) / (2G), u_e = sigma_HEL / (rho c_L), with the hot
    plates' density and bulk sound speed, G the draw's shear modulus, and Johnson-Cook's initial flow
    stress Y0 = A (1 + C ln(rate / rate_0)) (1 - T0*^m) at SPLIT_STRAIN_RATE_PER_S (no hardening), its columns
    read by the roles the candidate's law declares (`Law.role_column`: yield_stress, rate_coefficient,
    thermal_exponent); InputError for a law that declares them not."""
    yield_stress, rate_coefficient, thermal_exponent = _role_columns(
        candidate.model, ("yield_stress", "rate_coefficient", "thermal_exponent"))
    rho = material.initial_density_g_cc(candidate.initial_temperature_K)
    c_bulk = material.bulk_sound_speed_m_s(candidate.initial_temperature_K) / CM_US_TO_M_S   # cm/us
    g = design[SHEAR_MODULUS].to_numpy(float)
    c_l = np.sqrt(c_bulk**2 + 4.0 * g / (3.0 * rho))
    t0 = material.T_ref_K if candidate.initial_temperature_K is None else candidate.initial_temperature_K
    t_star = max(0.0, (t0 - material.T_ref_K) / (material.T_melt_K - material.T_ref_K))
    thermal = 1.0 - t_star ** design[thermal_exponent].to_numpy(float) if t_star > 0 else 1.0
    rate = 1.0 + design[rate_coefficient].to_numpy(float) * math.log(SPLIT_STRAIN_RATE_PER_S * PER_S_TO_PER_US
                                                                   / material.rate_ref_per_us())
    y0 = design[yield_stress].to_numpy(float) * rate * thermal
    sigma_hel = y0 * (rho * c_bulk**2 + 4.0 * g / 3.0) / (2.0 * g)
    return sigma_hel / (rho * c_l) * CM_US_TO_M_S


def _role_columns(model: str, roles: Sequence[str]) -> list[str]:
    """The design columns of `roles` in law `model` (`Law.role_column`); InputError naming a role it lacks."""
    law = get_law(model)
    columns = [law.role_column(role) for role in roles]
    missing = [role for role, column in zip(roles, columns, strict=True) if column is None]
    if missing:
        raise InputError(f"{law.name}: the elastic-precursor check reads a law's {', '.join(roles)}; "
                         f"{law.name} declares no {', '.join(missing)}")
    return columns


def check_split(design: pd.DataFrame, candidate: Candidate, material: MaterialProperties, where: str) -> None:
    """The candidate's impact must drive a plastic wave behind the elastic precursor: in a symmetric
    impact the particle velocity is half the impact velocity, which must exceed the HEL's
    (`hel_particle_velocity_m_s`) for the typical draw: an InputError naming `where`, before any run,
    when it does not for SPLIT_SHARE of the draws or more. (Not the tail: the thermal factor is taken at
    T0, and the posterior's low-m draws, whose strength a kelvin of the precursor's own heating removes,
    read high; at 298 K their 95th percentile is 113 m/s against 42 m/s median, 35 m/s measured in 104S.)"""
    u_e = hel_particle_velocity_m_s(design, candidate, material)
    u_p = 0.5 * design[VELOCITY].to_numpy(float) * CM_US_TO_M_S
    share = float(np.mean(u_p <= u_e))
    if share >= SPLIT_SHARE:
        raise InputError(
            f"{where}: velocity_m_s {candidate.velocity_m_s:g} gives a particle velocity of {np.median(u_p):.3g} m/s, "
            f"not above the HEL's ({np.median(u_e):.3g} m/s median over the posterior draws) for {share:.0%} of "
            "them: no plastic wave separates from the elastic precursor; raise the velocity")


def check_design(design: pd.DataFrame, names: Sequence[str], source: str) -> pd.DataFrame:
    """A candidate design read back: the columns `candidate_design` writes, finite; an InputError names
    the file and the column otherwise."""
    from shockcal.io import require_columns

    needed = ["run", *names, LAMBDA_Y, VELOCITY_FACTOR, SLOPE, VELOCITY, SHEAR_MODULUS]
    require_columns(design, needed, source)
    for name in needed:
        if not np.all(np.isfinite(pd.to_numeric(design[name], errors="coerce").to_numpy(float))):
            raise InputError(f"{source}: column {name} has a value that is not a finite number")
    return design


def score_candidate(features: pd.DataFrame, design: pd.DataFrame, feature_names: Sequence[str],
                    parameters: Sequence[str], targets: Sequence[str], sd_fraction: float,
                    readout_sd_m_s: Sequence[float], seed: int) -> dict:
    """One candidate's expected information gain (`shockcal.campaign.next_shot`) from its runs' features.

    Args:
        features: the features table of the candidate's runs (`run`, `status`, the features; m/s).
        design: the candidate's design (`candidate_design`).
        feature_names: the measured features (the calibration's four velocities).
        parameters: theta, the design columns the gain is about besides `lambda_y` (every input and the
            nuisance inputs).
        targets: the parameters of interest (a subset of `parameters`).
        sd_fraction: the observation error, a fraction of each feature (`observed.sd_fraction`).
        readout_sd_m_s: the extractor's read-out sd per feature (m/s).
        seed: the seed of the outer samples and the bootstrap.

    Failed runs are left out (their count is `n_failed`: a run that fails at the candidate is a
    candidate the hydrocode cannot read, and the gain is then over the draws it can). Returns a row:
    eig_nats and eig_sd about the targets jointly (Gaussian entropy bound), eig_full_nats,
    eig_full_sd, eig_full_lower_nats and resolved (all of theta: the nested estimate and its PCE
    lower bound), inner_ess, per target its marginal gain (eig_<p>_nats, eig_<p>_sd), prior and
    expected posterior sd (prior_sd_<p>, expected_sd_<p>, its input's unit), and per feature the
    spread of the draws' features (feature_sd_<f>) and the median measurement noise (noise_sd_<f>), m/s.
    """
    from shockcal.campaign.next_shot import expected_information_gain, noise_sd

    table = design.merge(features[["run", "status", *feature_names]], on="run", how="left", validate="one_to_one")
    ok = (table["status"] == "ok").to_numpy() & np.isfinite(table[list(feature_names)].to_numpy(float)).all(axis=1)
    if ok.sum() < 10:
        raise InputError(f"candidate runs: only {int(ok.sum())} of {len(table)} runs gave features; at least 10 "
                         "are needed for an information gain")
    table = table[ok]
    g = table[list(feature_names)].to_numpy(float)
    sd = noise_sd(g, sd_fraction, np.asarray(readout_sd_m_s, float), table[LAMBDA_Y].to_numpy(float))
    names = [*parameters, LAMBDA_Y]
    theta = table[names].to_numpy(float)
    joint = expected_information_gain(g, sd, np.random.default_rng(seed), targets=list(targets), theta=theta,
                                      names=names)
    row = {"eig_nats": joint.eig, "eig_sd": joint.eig_sd, "method": joint.method, "eig_full_nats": joint.eig_full,
           "eig_full_sd": joint.eig_full_sd, "eig_full_lower_nats": joint.eig_full_lower, "resolved": joint.resolved,
           "inner_ess": joint.inner_ess, "n_draws": len(table), "n_failed": int((~ok).sum())}
    for i, target in enumerate(targets):
        one = expected_information_gain(g, sd, np.random.default_rng([seed, i]), targets=[target], theta=theta,
                                        names=names)
        row.update({f"eig_{target}_nats": one.eig, f"eig_{target}_sd": one.eig_sd,
                    f"prior_sd_{target}": joint.prior_sd[i], f"expected_sd_{target}": joint.posterior_sd[i]})
    for j, feature in enumerate(feature_names):
        row.update({f"feature_sd_{feature}": float(g[:, j].std(ddof=1)), f"noise_sd_{feature}": float(np.median(sd[:, j]))})
    return row


def ranking_table(rows: Sequence[dict]) -> pd.DataFrame:
    """The candidates' rows (`candidate`, the conditions, `score_candidate`'s columns) ranked by
    eig_nats, best first, with `rank` and `overlaps_best`: whether the candidate's eig_nats +- 2 eig_sd
    reaches the best one's eig_nats - 2 eig_sd (the two cannot be told apart at that noise)."""
    if not rows:
        raise InputError("no candidates to rank: next_shot.candidates is empty")
    table = pd.DataFrame(rows).sort_values("eig_nats", ascending=False, kind="stable").reset_index(drop=True)
    best = table.iloc[0]
    table.insert(1, "rank", np.arange(1, len(table) + 1))
    table["overlaps_best"] = table["eig_nats"] + 2 * table["eig_sd"] >= best["eig_nats"] - 2 * best["eig_sd"]
    return table

