"""Which shot next (`shockcal suggest-shot`): the candidates' expected information gain and why.

Input: the ranking table (results/next_shot/ranking.csv; `shockcal.campaign.candidates.ranking_table`). Left:
per candidate (best at the top) the expected information gain about the targets jointly (eig_nats)
and about each target alone (eig_<p>_nats), with +- 2 bootstrap sd bars. Right: per candidate and
calibration feature, the spread of the draws' features (their sd over the posterior draws) over the
noise sd (1% of the feature, with the read-out sd and the emulator's error when the ranking has
them): where it is below 1 the feature cannot tell the draws apart.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from shockcal.plots.style import CALIBRATION_FEATURES, COLORS, no_data, styled, subplots


@styled
def next_shot_ranking(ranking: pd.DataFrame | None, targets: list[str]):
    """The ranking's information gains (left) and feature spread against the noise (right)."""
    n = 1 if ranking is None else max(len(ranking), 1)
    fig, axes = subplots(1, 2, width=10.0, height=1.6 + 0.5 * n, sharey=True)
    gain, spread = axes[0]
    if ranking is None or ranking.empty:
        for ax in (gain, spread):
            no_data(ax, "no ranking" if ranking is None else "ranking empty")
        return fig
    ranking = ranking.sort_values("eig_nats", ascending=False)
    y = np.arange(len(ranking))[::-1].astype(float)
    series = [("eig", f"{', '.join(targets)} jointly", COLORS["posterior"])]
    palette = ["#e07b00", "#2b9348", "#6a3d9a", "#8c564b", "#d62728", "#17becf"]
    series += [(f"eig_{t}", t, palette[i % len(palette)]) for i, t in enumerate(targets)
               if f"eig_{t}_nats" in ranking.columns]
    step = 0.8 / len(series)
    for i, (prefix, label, color) in enumerate(series):
        offset = 0.4 - step * (i + 0.5)
        gain.errorbar(ranking[f"{prefix}_nats"], y + offset, xerr=2 * ranking[f"{prefix}_sd"], fmt="o", ms=3,
                      color=color, label=label, capsize=2)
    gain.axvline(0, color="0.6", lw=0.6)
    gain.set_yticks(y, ranking["candidate"])
    gain.set_xlabel("expected information gain (nats), +- 2 bootstrap sd")
    gain.legend(fontsize=7, loc="best")
    markers = ["o", "s", "^", "D"]
    for j, feature in enumerate(f for f in CALIBRATION_FEATURES if f"feature_sd_{f}" in ranking.columns):
        ratio = ranking[f"feature_sd_{feature}"] / ranking[f"noise_sd_{feature}"]
        spread.plot(ratio, y + 0.3 - 0.2 * j, markers[j % 4], ms=4, label=feature, color=palette[j % len(palette)])
    spread.axvline(1.0, color=COLORS["measurement"], lw=0.8, ls="--", label="= the noise")
    spread.set_xscale("log")
    spread.set_xlabel("features' spread over the draws / noise sd")
    spread.legend(fontsize=7, loc="best")
    fig.suptitle(f"Which shot next: {len(ranking)} candidates, {int(ranking['n_draws'].max())} joint-posterior "
                 "draws each through the hydrocode")
    return fig
