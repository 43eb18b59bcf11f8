"""Our hydrocode and extractor against the paper's FLAG features (../shared/data/al5083, runs 0-499).

`make validate` compares all 500 runs of every shot (docs/hydro.md); these tests keep two of its
findings from regressing at a test's cost: the single-wave traces of 104S, where the early/late
split decides what "elastic plateau" means, and the plateaus on a fixed sample of the design.

Since 2026-11-29 the rate term is read at the step's plastic rate inside the return (issue 62; FLAG reads
the total rate beside it): our elastic precursor stands above FLAG's, by +3.4 to +4.6 m/s on the sample
and +15 m/s in the merged-wave runs (docs/hydro.md, "Against FLAG"). The bounds below hold today's
differences with a margin; the plastic plateau keeps its goal.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from shockcal.simulators.builtin import simulate_design
from shockcal.study.adapters import extractor_settings, hydro_inputs, shot_mapping
from shockcal.velocimetry.feature_tables import features_table

# The ten 104S runs (A 390-950 MPa: one merged wave) where a cut-off 80 ns after arrival put a broad
# second component into the elastic mixture: v_elastic 16-33 m/s above FLAG's (RMSE 22 m/s), v_slope1 13-28.
SINGLE_WAVE_RUNS_104S = [202, 248, 212, 354, 418, 421, 292, 466, 289, 52]
SAMPLE_STRIDE = 25      # runs 0, 25, ..., 475 of each shot for the slow check
PLASTIC_RMSE_GOAL_M_S = 2.5                 # v_plastic against FLAG, met in every shot
ELASTIC_BIAS_M_S = (2.0, 7.0)               # ours - FLAG, mean over the sample: the rate convention's (3.4-4.6)
ELASTIC_SCATTER_M_S = 5.0                   # its sd over the sample (3.3-4.5)


def errors_against_flag(reference_data, config, shot, runs) -> tuple[pd.DataFrame, pd.DataFrame]:
    """(our features, FLAG's) for the given design runs of one shot, indexed by run."""
    design = pd.read_csv(reference_data / "design.csv")
    flag = pd.read_csv(reference_data / f"flag_features_{shot}.csv").set_index("run")
    traces = simulate_design(design[design["run"].isin(runs)], shot_mapping(config, shot),
                             *hydro_inputs(config, config["shots"][shot]))
    ours = features_table(traces, extractor_settings(config, shot)).set_index("run")
    assert (ours["status"] == "ok").all(), ours.loc[ours["status"] != "ok", "reason"]
    return ours, flag.loc[ours.index]


def rmse(a, b) -> float:
    return float(np.sqrt(np.mean((np.asarray(a) - np.asarray(b)) ** 2)))


def test_single_wave_traces_read_the_elastic_plateau_like_flag(reference_data, paper_config):
    ours, flag = errors_against_flag(reference_data, paper_config, "104S", SINGLE_WAVE_RUNS_104S)
    error = ours["v_elastic"] - flag["v_elastic"]
    assert rmse(ours["v_elastic"], flag["v_elastic"]) < 20.0, error.round(1).to_dict()   # measured 17.2 (6.6 before
    assert error.abs().max() < 30.0, error.round(1).to_dict()                           # 2026-11-29); 23.3 (12.7)
    assert (ours["v_elastic"] < ours["v_plastic"]).all()          # the split reads a precursor below the plateau
    assert rmse(ours["v_plastic"], flag["v_plastic"]) < 4.0                              # measured 2.7
    # the first slope point follows (measured RMSE 15.0 m/s; 4.3 before 2026-11-29, 18 with the late cut-off)
    assert rmse(ours["v_slope1"], flag["v_slope1"]) < 18.0


@pytest.mark.slow
@pytest.mark.parametrize("shot", ["104S", "105S", "106S"])
def test_goals_met_on_a_fixed_sample_of_the_design(reference_data, paper_config, shot):
    ours, flag = errors_against_flag(reference_data, paper_config, shot, list(range(0, 500, SAMPLE_STRIDE)))
    # The rise-time bias goal (15 ns) is judged by `make validate` on all 500 runs only: per run the
    # rise time scatters by 72 ns RMSE in 104S, so the mean of 20 runs has a standard error of ~16 ns.
    assert rmse(ours["v_plastic"], flag["v_plastic"]) <= PLASTIC_RMSE_GOAL_M_S
    elastic = ours["v_elastic"] - flag["v_elastic"]
    assert ELASTIC_BIAS_M_S[0] <= elastic.mean() <= ELASTIC_BIAS_M_S[1], elastic.round(1).to_dict()
    assert elastic.std() <= ELASTIC_SCATTER_M_S, elastic.round(1).to_dict()
