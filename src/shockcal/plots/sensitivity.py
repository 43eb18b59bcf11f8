"""Sobol indices of the emulated features (`shockcal sensitivity`): which input moves which feature.

Input: the Sobol table (`domain`, `shot`, `feature`, `input`, `S1`, `S1_conf`, `ST`, `ST_conf`). One
panel per domain (rows: the prior box, the joint posterior's 5-95% box) and shot (columns): a heat map
of the total index ST of each feature (rows) and input (columns), each cell labelled ST over (S1).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from shockcal.plots.style import CALIBRATION_FEATURES, input_symbol, no_data, styled, subplots

DOMAIN_TITLES = {"prior": "prior box", "posterior_q05_q95": "joint posterior's 5-95% box"}


@styled
def sobol_indices(table: pd.DataFrame | None, shots: list[str]):
    """Heat maps of total Sobol indices, first-order ones in brackets (rows: domains, columns: shots)."""
    domains = list(DOMAIN_TITLES) if table is None or table.empty else list(dict.fromkeys(table["domain"]))
    fig, axes = subplots(len(domains), len(shots), width=3.6 * len(shots), height=2.6 * len(domains) + 0.6)
    if table is None or table.empty:
        for ax in axes.flat:
            no_data(ax, "no Sobol table" if table is None else "Sobol table empty")
        return fig
    image = None
    for r, domain in enumerate(domains):
        for c, shot in enumerate(shots):
            ax = axes[r, c]
            rows = table[(table["domain"] == domain) & (table["shot"].astype(str) == shot)]
            if rows.empty:
                no_data(ax, f"no indices for {shot}")
                continue
            inputs = list(dict.fromkeys(rows["input"]))
            features = [f for f in CALIBRATION_FEATURES if f in set(rows["feature"])]
            total = rows.pivot(index="feature", columns="input", values="ST").loc[features, inputs]
            first = rows.pivot(index="feature", columns="input", values="S1").loc[features, inputs]
            image = ax.imshow(np.clip(total.to_numpy(float), 0, 1), cmap="Blues", vmin=0, vmax=1, aspect="auto")
            for i in range(len(features)):
                for j in range(len(inputs)):
                    st, s1 = total.iat[i, j], first.iat[i, j]
                    ax.text(j, i, f"{st:.2f}\n({s1:.2f})", ha="center", va="center", fontsize=6,
                            color="white" if st > 0.6 else "black")
            ax.set_xticks(range(len(inputs)), [input_symbol(k) for k in inputs])
            ax.set_yticks(range(len(features)), features if c == 0 else [""] * len(features))
            ax.set_title(f"{shot}: {DOMAIN_TITLES.get(domain, domain)}")
            ax.spines[:].set_visible(False)
    if image is not None:
        fig.colorbar(image, ax=axes, shrink=0.6, label="total Sobol index ST (first order S1 in brackets)")
    fig.suptitle("Sobol indices of the emulated features (SALib; bootstrap intervals in the table)")
    return fig
