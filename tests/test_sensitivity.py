"""Sobol indices (shockcal.campaign.sensitivity, SALib): the Ishigami function's known indices within the bootstrap
intervals, the per-shot emulator wrapper on a model with known indices, and the one-line errors."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from shockcal.campaign.sensitivity import emulator_sobol, posterior_box, sobol_indices
from shockcal.errors import InputError

pytest.importorskip("SALib")


def ishigami(x, a=7.0, b=0.1):
    return np.sin(x[:, 0]) + a * np.sin(x[:, 1]) ** 2 + b * x[:, 2] ** 4 * np.sin(x[:, 0])


def test_ishigami_indices_lie_within_their_bootstrap_intervals():
    table = sobol_indices(ishigami, ["x1", "x2", "x3"], [-np.pi] * 3, [np.pi] * 3, n_base=1024, seed=1)
    table = table.set_index("input")
    known = pd.DataFrame({"S1": [0.314, 0.442, 0.0], "ST": [0.558, 0.442, 0.244]}, index=["x1", "x2", "x3"])
    for index in ("S1", "ST"):
        error = (table[index] - known[index]).abs()
        assert (error <= table[f"{index}_conf"]).all(), table
        assert (table[f"{index}_conf"] < 0.1).all(), table          # and the intervals are informative


class LinearEmulator:
    """Two shots; features linear in the inputs, so S1 = ST = c_i^2 / sum c_j^2 on a box of equal widths."""

    feature_names = ["v_elastic", "v_plastic"]
    inputs = {"104S": ["A", "V1"], "105S": ["A", "B", "V2"]}
    shots = list(inputs)

    def required_inputs(self, shots):
        return self.inputs[shots[0]]

    def predict(self, inputs, shots):
        if shots == ["104S"]:
            mean = np.column_stack([3 * inputs["A"] + inputs["V1"], inputs["V1"]])
        else:
            mean = np.column_stack([inputs["A"] + inputs["B"] + inputs["V2"], 2 * inputs["B"] + 1e-9 * inputs["A"]])
        return mean, np.zeros((len(mean), 2, 2))


def test_emulator_sobol_per_shot_on_its_own_inputs():
    bounds = {"A": (0.0, 1.0), "B": (2.0, 3.0), "V1": (0.0, 1.0), "V2": (5.0, 6.0), "unused": (0.0, 1.0)}
    table = emulator_sobol(LinearEmulator(), ["104S", "105S"], bounds, n_base=512, seed=2, batch=100)
    assert list(table.columns) == ["shot", "feature", "input", "S1", "S1_conf", "ST", "ST_conf"]
    assert set(table.loc[table["shot"] == "104S", "input"]) == {"A", "V1"}
    st = table.set_index(["shot", "feature", "input"])["ST"]
    assert st["104S", "v_elastic", "A"] == pytest.approx(0.9, abs=0.03)
    assert st["104S", "v_plastic", "V1"] == pytest.approx(1.0, abs=0.02)
    assert st["105S", "v_elastic", "B"] == pytest.approx(1 / 3, abs=0.03)
    assert st["105S", "v_plastic", "B"] == pytest.approx(1.0, abs=0.02)


def test_constant_output_reads_nan():
    table = sobol_indices(lambda x: np.column_stack([x[:, 0], np.ones(len(x))]), ["a", "b"], [0, 0], [1, 1],
                          n_base=64, seed=0)
    assert table.loc[table["output"] == "y1", ["S1", "ST"]].isna().all().all()
    assert table.loc[(table["output"] == "y0") & (table["input"] == "a"), "ST"].item() == pytest.approx(1, abs=0.05)


def test_bad_input_is_named():
    with pytest.raises(InputError, match="n_base 1000 is not a power of 2"):
        sobol_indices(ishigami, ["x1", "x2", "x3"], [0] * 3, [1] * 3, n_base=1000, seed=0)
    with pytest.raises(InputError, match="empty box for inputs \\['x2'\\]"):
        sobol_indices(ishigami, ["x1", "x2", "x3"], [0] * 3, [1, 0, 1], n_base=64, seed=0)
    with pytest.raises(InputError, match="no bounds for inputs \\['V1'\\]"):
        emulator_sobol(LinearEmulator(), ["104S"], {"A": (0, 1)}, n_base=64, seed=0)
    summary = pd.DataFrame({"parameter": ["A", "B"], "q05": [0.1, 0.2], "q95": [0.3, 0.4]})
    assert posterior_box(summary, ["B"]) == {"B": (0.2, 0.4)}
    with pytest.raises(InputError, match="no rows for inputs \\['C'\\]"):
        posterior_box(summary, ["C"])
    in_mpa = pd.DataFrame({"parameter": ["A_MPa"], "q05": [150.0], "q95": [250.0]})   # Posterior.summary()'s rows
    assert posterior_box(in_mpa, ["A"], {"A": ("A_MPa", "MPa", 1.0e5)}) == {"A": (0.0015, 0.0025)}
