"""Posterior predictions: emulator predictions of the calibration features at a design of posterior
draws (`shockcal.design.posterior_draws.draw_posterior_design` draws it).
"""

from __future__ import annotations

import numpy as np
import pandas as pd


def emulator_predictions(emulator, design: pd.DataFrame, shots: list[str]) -> pd.DataFrame:
    """Emulator mean and sd (m/s) of the calibration features at every design row, for each shot.

    One row per (run, shot): `run`, `shot`, the features (e.g. `v_elastic`, the predictive mean)
    and their predictive sd (`v_elastic_sd`, emulator uncertainty, no observation error).
    """
    inputs = {name: design[name].to_numpy(float) for name in design.columns if name != "run"}
    mean, cov = emulator.predict(inputs, shots)
    sd = np.sqrt(np.clip(np.diagonal(cov, axis1=1, axis2=2), 0.0, None))
    names = list(emulator.feature_names)
    parts = []
    for i, shot in enumerate(shots):
        cols = slice(len(names) * i, len(names) * (i + 1))
        part = pd.DataFrame(mean[:, cols], columns=names)
        part[[f"{n}_sd" for n in names]] = sd[:, cols]
        part.insert(0, "shot", shot)
        part.insert(0, "run", design["run"].to_numpy())
        parts.append(part)
    return pd.concat(parts, ignore_index=True)
