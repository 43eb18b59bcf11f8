"""The measured features against the training runs (shockcal.inference.training_range): a feature
outside the training runs' widened range stops a calibration in one line naming the shot, the feature,
the value and the range; `checks.features_in_training_range: false` lets it pass with a warning; the
study's emulator hands its training features to the check; the report's figure draws the band."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from shockcal.errors import InputError
from shockcal.inference.calibration import calibrate
from shockcal.inference.training_range import RANGE_MARGIN, TrainingRange, check_training_range, training_ranges
from shockcal.study.adapters import calibration_settings
from shockcal.velocimetry.columns import CALIBRATION_FEATURES

TRAINING = pd.DataFrame({"v_elastic": np.linspace(20.0, 40.0, 40), "v_plastic": np.linspace(480.0, 520.0, 40),
                         "v_slope1": np.linspace(52.0, 102.0, 40), "v_slope2": np.linspace(428.0, 475.0, 40)})
INSIDE = {"v_elastic": 30.0, "v_plastic": 500.0, "v_slope1": 66.8, "v_slope2": 452.7}


def test_the_band_is_the_range_widened_by_the_margin():
    limits = training_ranges({"S": TRAINING}, ["v_slope1"])["S"]["v_slope1"]
    assert (limits.low_m_s, limits.high_m_s) == (52.0, 102.0)
    assert limits.band() == pytest.approx((52.0 - RANGE_MARGIN * 50, 102.0 + RANGE_MARGIN * 50))
    assert TrainingRange(52.0, 102.0).distance(77.0) == 0.0 and TrainingRange(52.0, 102.0).distance(152.0) == 1.0


@pytest.mark.parametrize("feature, value", [("v_slope1", 150.0), ("v_slope2", 371.0), ("v_elastic", 489.2)])
def test_a_feature_outside_the_training_runs_stops_in_one_line(feature, value):
    with pytest.raises(InputError) as err:
        check_training_range({"cu500": {**INSIDE, feature: value}}, {"cu500": TRAINING}, "observed.parquet")
    message = str(err.value)
    limits = training_ranges({"s": TRAINING}, [feature])["s"][feature]
    assert "\n" not in message and message.startswith("observed.parquet: shot cu500: ")
    assert f"measured {feature} = {value:.1f} m/s" in message
    assert f"all 40 training runs [{limits.low_m_s:.1f}, {limits.high_m_s:.1f}] m/s" in message
    assert "checks.features_in_training_range: false" in message


def test_features_inside_the_band_pass_and_the_key_lets_an_outside_one_pass(caplog):
    edge = {**INSIDE, "v_slope1": 102.0 + 0.9 * RANGE_MARGIN * 50}       # beyond the range, inside the band
    check_training_range({"cu500": edge}, {"cu500": TRAINING}, "obs")
    assert caplog.text == ""
    check_training_range({"cu500": {**INSIDE, "v_slope1": 150.0}}, {"cu500": TRAINING}, "obs", enabled=False)
    assert "measured v_slope1 = 150.0 m/s" in caplog.text and "accepted: checks.features_in_training_range" in caplog.text


class TrainedStandIn:
    """An emulator with training runs and a constant prediction at the training runs' centre, 100 m/s sd: the
    measured features lie inside the prediction's spread, so the posterior sits in the prior's bulk and the
    sampling after the check is short (with 1 m/s it chased lambda_y to its prior's far tail: 20-40 s)."""

    feature_names = CALIBRATION_FEATURES

    def required_inputs(self, shots):
        return ["A"]

    def input_bounds(self, names):
        return np.array([0.0005]), np.array([0.01])

    def predict(self, inputs, shots):
        n = len(np.atleast_1d(inputs["A"]))
        return np.tile(TRAINING.mean().to_numpy(), (n, 1)), np.tile(100.0**2 * np.eye(4), (n, 1, 1))

    def error_groups(self, shots):
        from shockcal.emulator.error_model import ErrorModel

        return [(np.arange(4 * len(shots)), ErrorModel())]

    def training_features(self, shot):
        return TRAINING


def test_calibrate_checks_before_it_samples_and_the_config_key_lets_it_pass(paper_config, caplog):
    """`calibrate` (the calibrate stage, the sequential waves' calibrations) stops before sampling;
    `checks.features_in_training_range: false` reaches it through `calibration_settings`; the synthetic-truth
    check's settings only warn."""
    row = {"shot": "104S", "t_jumpoff": 0.9, "t_elastic": 0.95, "t_plastic": 1.8, "t_slope1": 1.0, "t_slope2": 1.1,
           "v_jumpoff": 2.0, **INSIDE, "v_slope1": 150.0}
    observed = pd.DataFrame([row])
    paper_config["checks"]["plateau_vs_velocity"] = False
    paper_config["calibration"].update(n_live=50, n_eff=100, draws=100)
    with pytest.raises(InputError, match="obs.csv: shot 104S: measured v_slope1 = 150.0 m/s is outside"):
        calibrate(TrainedStandIn(), ["104S"], observed, calibration_settings(paper_config, ["104S"]), source="obs.csv")
    assert calibration_settings(paper_config, ["104S"], check=True).check_training_range is False
    paper_config["checks"]["features_in_training_range"] = False
    posterior = calibrate(TrainedStandIn(), ["104S"], observed, calibration_settings(paper_config, ["104S"]))
    assert len(posterior.draws) == 100 and "measured v_slope1 = 150.0 m/s" in caplog.text


def test_the_study_emulator_hands_each_shot_its_training_features():
    from shockcal.emulator.study_emulator import Block, Emulator

    class Model:                    # the two attributes a block's model is read for
        y_train = np.column_stack([TRAINING.to_numpy(), TRAINING.to_numpy() + 1000.0])
        _input_names: list = []

    class Map:
        names, powers, yield_input = ["A"], [], None

    emulator = Emulator("joint", [Block(Map(), ["S1", "S2"], np.arange(40) + 7, Model())], {"A": (0, 1)}, {})
    second = emulator.training_features("S2")
    assert list(second.columns) == CALIBRATION_FEATURES and list(second.index[:2]) == [7, 8]
    np.testing.assert_array_equal(second.to_numpy(), TRAINING.to_numpy() + 1000.0)
    with pytest.raises(InputError, match="no shot"):
        emulator.training_features("S3")


def test_the_report_figure_is_registered_and_names_a_feature_outside(paper_config):
    from shockcal.study.figure_catalogue import FigureInputs, catalogue

    spec = catalogue(paper_config)["features_vs_training"]
    assert spec.target == "all" and set(spec.needs) == {"features:104S", "features:105S", "features:106S", "observed"}
    from shockcal.plots.training_range import measured_against_training

    observed = pd.DataFrame([{"shot": "S", **INSIDE, "v_slope1": 150.0}])
    fig = measured_against_training({"S": TRAINING.assign(status="ok")}, observed, ["S"], 0.01)
    titles = [ax.get_title() for ax in fig.axes]
    assert titles.count("outside the training runs") == 1
    assert "outside" in titles[CALIBRATION_FEATURES.index("v_slope1")]
    assert FigureInputs().table("observed") is None
