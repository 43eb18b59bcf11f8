"""An emulator scored on hydrocode runs it was not fitted on: the error of its mean and whether its error
model's central band holds them (what a K-fold on the training design cannot say where the design is
crowded into the posterior; docs/sequential.md)."""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy import stats

from shockcal.emulator.study_emulator import Emulator


def score_heldout(emulator: Emulator, design: pd.DataFrame, features: dict[str, pd.DataFrame],
                  level: float = 0.9) -> pd.DataFrame:
    """The emulator's mean and band at held-out runs, per feature of every shot and over all of them.

    design: the runs' inputs (a `run` column and the design columns, in the design's native units);
    features: shot -> that shot's features table (`run`, `status`, the feature columns in m/s); only the
    runs with status "ok" for every shot are scored. Each feature's band is the central `level` interval
    of its block's error model, t_dof(0, scale sd^2), a Gaussian when dof is infinite.

    Returns one row per shot and feature (`feature` "shot:name") and a last row `all (N runs)`:
    `rmse_m_s` (root mean square of mean - simulated, m/s), `coverage` (share inside the band),
    `mean_z2` (mean squared error over the emulator's predictive variance: 1 when its sd is honest
    before the error model's scale) and `n_values`."""
    shots = list(features)
    ok = {s: t[t["status"] == "ok"].set_index("run") for s, t in features.items()}
    runs = sorted(set.intersection(*(set(t.index) for t in ok.values())))
    rows = design.set_index("run").loc[runs]
    mean, cov = emulator.predict({k: rows[k].to_numpy() for k in rows.columns}, shots)
    truth = np.column_stack([ok[s].loc[runs, f].to_numpy(float) for s in shots for f in emulator.feature_names])
    err = mean - truth
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
    return pd.concat([table, pd.DataFrame([overall])], ignore_index=True)
