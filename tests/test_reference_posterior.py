"""The documented shape of the reference joint posterior under the Student-t emulator error, on the
paper's published features (docs/calibration.md, "Reference posterior, Student-t emulator error, the
paper's published features"), checked on its saved draws
(tests/data/reference_posterior_joint.parquet, made by tests/data/make_reference_posterior.py).

Each claim is tested with a margin of several binomial standard errors of the 6,000 draws, so the
test fails if a remade reference changes the claim, not if it only moves within its sampling noise.
"""
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

DRAWS = Path(__file__).parent / "data" / "reference_posterior_joint.parquet"
TIP_A_MBAR = 0.008  # A > 800 MPa


@pytest.fixture(scope="module")
def draws() -> pd.DataFrame:
    return pd.read_parquet(DRAWS)


def density(x: np.ndarray, edges: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Histogram density and its binomial standard error per bin."""
    counts, _ = np.histogram(x, edges)
    share = counts / len(x)
    width = np.diff(edges)
    return share / width, np.sqrt(share * (1 - share) / len(x)) / width


def test_the_a_above_800_mpa_tip_holds_about_four_percent_of_the_mass(draws):
    """0.037 with the Student-t emulator error (0.120 under the Gaussian one, docs/calibration.md)."""
    tip = np.mean(draws["A"] > TIP_A_MBAR)
    se = np.sqrt(tip * (1 - tip) / len(draws))
    assert abs(tip - 0.037) < 4 * se, f"tip mass {tip:.3f}"
    # the tip is the small-m arm: m there is below 0.15 for most of its mass
    assert np.median(draws.loc[draws["A"] > TIP_A_MBAR, "m"]) < 0.15


def test_n_is_bimodal(draws):
    """A mode at n < 0.1, a dip at 0.2-0.3 and a broad second mode at 0.4-0.7: both peaks stand above
    the dip by more than 4 standard errors of their difference."""
    d, se = density(draws["n"].to_numpy(), np.arange(0.0, 1.51, 0.1))
    low, dip, second = 0, 2, 4
    for peak in (low, second):
        assert d[peak] - d[dip] > 4 * np.hypot(se[peak], se[dip]), (peak, d.round(2))
    assert np.argmax(d[3:8]) + 3 in (4, 5, 6), d.round(2)  # the second mode sits at 0.4-0.7


def test_m_is_a_spike_at_zero_over_a_plateau_without_a_second_mode(draws):
    """m's density below 0.1 stands above the plateau by more than 4 standard errors; over 0.5-3 it
    follows a straight line (a mild rise towards the box's end, no second mode): every 0.25-wide bin
    lies within 4 standard errors of the line fitted to them."""
    m = draws["m"].to_numpy()
    d, se = density(m, np.arange(0.0, 3.01, 0.1))
    assert d[0] - np.median(d[5:]) > 4 * np.hypot(se[0], np.median(se[5:])), d.round(2)
    edges = np.arange(0.5, 3.01, 0.25)
    plateau, se = density(m, edges)
    centres = 0.5 * (edges[1:] + edges[:-1])
    line = np.polyval(np.polyfit(centres, plateau, 1, w=1 / se), centres)
    assert np.all(np.abs(plateau - line) < 4 * se), plateau.round(3)


def test_delta3_sits_at_its_lower_bound(draws):
    assert np.mean(draws["Delta3"] < 0.04) > 0.8  # the lowest fifth of the box, 0-4 GPa (0.875)
