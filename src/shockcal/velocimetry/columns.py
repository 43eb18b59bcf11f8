"""The feature tables' column names, apart from the extractor so that a stage that only names the columns
(simulate, the emulator, the calibration, the config checks) does not load scipy's statistics with it."""

FEATURES = ("jumpoff", "elastic", "plastic", "slope1", "slope2")
COLUMNS = [f"{axis}_{name}" for name in FEATURES for axis in ("t", "v")]   # t_* in us, v_* in m/s
CALIBRATION_FEATURES = ["v_elastic", "v_plastic", "v_slope1", "v_slope2"]   # what the emulator and calibration use
READOUT_COLUMNS = [f"readout_sd_{column}" for column in CALIBRATION_FEATURES]   # m/s, in the observed table
RECORD_NOISE_COLUMNS = ["noise_sd_m_s", "noise_ar_order", "readout_half_window_ns"]
