"""An emulator scored on hydrocode runs it was not fitted on: the error of its mean and whether its error
model holds them, feature by feature (`score_heldout`) and as the 12-feature vector the calibration's
likelihood reads (`region_coverage`). A K-fold on the training design cannot say this where the design is
crowded into the posterior (docs/sequential.md)."""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy import stats

from shockcal.emulator.study_emulator import Emulator
from shockcal.errors import InputError


def score_heldout(emulator: Emulator, design: pd.DataFrame, features: dict[str, pd.DataFrame],
                  level: float = 0.9, records_sd_m_s=None) -> pd.DataFrame:
    """The emulator's mean and band at held-out runs, per feature of every shot and over all of them.

    design: the runs' inputs (a `run` column and the design columns, in the design's native units);
    features: shot -> that shot's features table (`run`, `status`, the feature columns in m/s); only the
    runs with status "ok" for every shot are scored. Each feature's band is the central `level` interval
    of its block's error model, t_dof(0, scale sd^2), a Gaussian when dof is infinite.
    records_sd_m_s: optional, the measured records' sd per shot and feature (m/s, shot-major in the order of
    `features`, as `Problem.obs_sd`): the error is then also read in it.

    Returns one row per shot and feature (`feature` "shot:name") and a last row `all (N runs)`:
    `rmse_m_s` (root mean square of mean - simulated, m/s), `coverage` (share inside the band),
    `mean_z2` (mean squared error over the emulator's predictive variance: 1 when its sd is honest
    before the error model's scale) and `n_values`; with `records_sd_m_s`, `records_sd_m_s` (over all, its
    root mean square) and `rmse_records_sd`, the RMSE over it (over all, the root mean square of the features'
    values: the scale on which the likelihood reads an error, below 1 where the records cannot tell it)."""
    shots, runs, err, cov = _heldout_errors(emulator, design, features)
    z = err / np.sqrt(np.diagonal(cov, axis1=1, axis2=2))
    half_width = np.empty(err.shape[1])
    for columns, error in emulator.error_groups(shots):
        half_width[columns] = np.sqrt(error.scale) * stats.t.ppf(0.5 + level / 2, error.dof)
    inside = np.abs(z) <= half_width
    table = pd.DataFrame({"feature": [f"{s}:{f}" for s in shots for f in emulator.feature_names],
                          "rmse_m_s": np.sqrt(np.mean(err ** 2, axis=0)), "coverage": inside.mean(axis=0),
                          "mean_z2": np.mean(z ** 2, axis=0), "n_values": len(runs)})
    overall = {"feature": f"all ({len(runs)} runs)", "rmse_m_s": float(np.sqrt(np.mean(err ** 2))),
               "coverage": float(inside.mean()), "mean_z2": float(np.mean(z ** 2)), "n_values": inside.size}
    table = pd.concat([table, pd.DataFrame([overall])], ignore_index=True)
    if records_sd_m_s is not None:
        records_sd = np.asarray(records_sd_m_s, dtype=float)
        if records_sd.shape != (err.shape[1],):
            raise InputError(f"{records_sd.size} records' sds for {err.shape[1]} features")
        ratio = table["rmse_m_s"].to_numpy()[:-1] / records_sd
        table["records_sd_m_s"] = [*records_sd, float(np.sqrt(np.mean(records_sd ** 2)))]
        table["rmse_records_sd"] = [*ratio, float(np.sqrt(np.mean(ratio ** 2)))]
    return table


def region_coverage(emulator: Emulator, design: pd.DataFrame, features: dict[str, pd.DataFrame],
                    level: float = 0.9) -> pd.DataFrame:
    """Whether the error model holds held-out runs as a vector: the share of runs whose errors e over a
    block's features lie in its central `level` region, e' C^-1 e / (F scale) <= the F(F, dof) distribution's
    `level` quantile (the region of t_dof(0, scale C) for the emulator covariance C; chi-square / F for a
    Gaussian). This is the density the calibration's likelihood uses; a feature's band (`score_heldout`)
    is one margin of it. Arguments as `score_heldout`.

    Returns one row per error block (`block`: its features' shots, e.g. "104S+105S+106S"): `n_features`,
    `coverage`, `n_runs`."""
    shots, runs, err, cov = _heldout_errors(emulator, design, features)
    rows = []
    for columns, error in emulator.error_groups(shots):
        e, c = err[:, columns], cov[:, columns][:, :, columns]
        d2 = np.einsum("ni,ni->n", e, np.linalg.solve(c, e[..., None])[..., 0])
        f = len(columns)
        limit = f * error.scale * (stats.chi2.ppf(level, f) / f if np.isinf(error.dof) else
                                   stats.f.ppf(level, f, error.dof))
        block = dict.fromkeys(shots[j // len(emulator.feature_names)] for j in columns)     # its shots, in order
        rows.append({"block": "+".join(block), "n_features": f, "coverage": float(np.mean(d2 <= limit)),
                     "n_runs": len(runs)})
    return pd.DataFrame(rows)


def _heldout_errors(emulator: Emulator, design: pd.DataFrame, features: dict[str, pd.DataFrame]):
    """The shots, the runs "ok" for every shot, and the emulator's errors (runs, F) = mean - simulated and
    covariances (runs, F, F) there, features shot after shot."""
    shots = list(features)
    ok = {s: t[t["status"] == "ok"].set_index("run") for s, t in features.items()}
    runs = sorted(set.intersection(*(set(t.index) for t in ok.values())))
    rows = design.set_index("run").loc[runs]
    mean, cov = emulator.predict({k: rows[k].to_numpy() for k in rows.columns}, shots)
    truth = np.column_stack([ok[s].loc[runs, f].to_numpy(float) for s in shots for f in emulator.feature_names])
    return shots, runs, mean - truth, cov
