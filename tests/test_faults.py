"""Bad input as a user meets it: every fault stops with a ShockcalError whose message names the file,
key or row (and, for a plausibility check, the unit that would fit and the opt-out); no traceback,
no silently wrong answer. The workflow-level faults (kill, truncated tables, lock, determinism) are
not here. Each case is (fault, error type, fragments the message must hold)."""

from __future__ import annotations

import errno
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from shockcal.cli import main, parse_pairs, parse_span
from shockcal.design.posterior_draws import draw_posterior_design
from shockcal.design.tables import latin_hypercube
from shockcal.emulator.error_model import ErrorModel
from shockcal.emulator.study_emulator import Emulator, training_data
from shockcal.errors import ConfigError, InputError, ShockcalError
from shockcal.inference.calibration import calibrate
from shockcal.inference.problem import Problem
from shockcal.io import atomic_path, read_table, read_tables, write_table
from shockcal.study.adapters import calibration_settings, load_study_design, shot_mapping
from shockcal.study.config import prior_bounds
from shockcal.study.validate import load_config, validate_config
from shockcal.velocimetry.feature_tables import check_failures
from shockcal.velocimetry.records import OPT_OUT, read_record

REPO = Path(__file__).resolve().parents[1]
CALIBRATION_FEATURES = ["v_elastic", "v_plastic", "v_slope1", "v_slope2"]


# ---- designs ------------------------------------------------------------------------------------

def _design(tmp, config, mutate, name="design.csv"):
    path = tmp / name
    mutate(latin_hypercube(prior_bounds(config), 5, seed=1)).to_csv(path, index=False)
    return path


def _set(frame, row, column, value):
    frame.loc[row, column] = value
    return frame


DESIGN_FAULTS = {
    "outside-box": (lambda d: _set(d, 1, "m", 3.5), ["run 1", "parameter m = 3.5", "inputs.m", "checks.design_box"]),
    "velocity-in-m/s": (lambda d: _set(d, 3, "V1", 204.0),
                        ["run 3", "impact velocity V1", "in m/s (204 m/s = 0.0204 cm/us)", "checks.design_box"]),
    "modulus-in-GPa": (lambda d: _set(d, 2, "G1", 30.0), ["run 2", "G1", "in GPa (30 GPa = 0.3 Mbar)"]),
    "duplicate-run": (lambda d: d.assign(run=[4, 4, 5, 6, 7]), ["run id 4 appears more than once"]),
    "nan": (lambda d: _set(d, 2, "A", np.nan), ["run 2: parameter A is not a finite number (nan)"]),   # no np.float64
    "text": (lambda d: d.assign(B=d["B"].astype(object)).pipe(_set, 4, "B", "0.002 Mbar"),
             ["run 4: parameter B is not a finite number ('0.002 Mbar')"]),
    "negative": (lambda d: _set(d, 0, "C", -0.01), ["run 0: parameter C", "negative"]),
    "missing-column": (lambda d: d.drop(columns="Delta3"), ["missing column(s) ['Delta3']"]),
}


@pytest.mark.parametrize("fault", DESIGN_FAULTS)
def test_design_faults(tmp_path, paper_config, fault):
    mutate, fragments = DESIGN_FAULTS[fault]
    path = _design(tmp_path, paper_config, mutate)
    with pytest.raises(InputError) as err:
        load_study_design(path, paper_config)
    for fragment in [str(path), *fragments]:
        assert fragment in str(err.value)


def test_design_unreadable_and_non_positive_velocity(tmp_path, paper_config):
    path = tmp_path / "design.csv"
    path.write_bytes(os.urandom(2000))
    with pytest.raises(InputError, match=f"table {path} could not be read"):
        load_study_design(path, paper_config)
    design = latin_hypercube(prior_bounds(paper_config), 3, seed=1).assign(V2=0.0)
    with pytest.raises(InputError, match="d.csv: run 0: impact velocity V2 = 0 must be positive for shot 105S"):
        shot_mapping(paper_config, "105S").check_positive(design, "d.csv")


def test_design_file_in_config_is_checked_at_load(tmp_path, paper_config):
    """A bad design.file stops every command (and snakemake) when the config is loaded."""
    paper_config["design"]["file"] = str(_design(tmp_path, paper_config, DESIGN_FAULTS["velocity-in-m/s"][0]))
    with pytest.raises(ConfigError, match=f"config.yaml: design.file: {tmp_path}/design.csv: run 3: impact velocity V1"):
        validate_config(paper_config, source="config.yaml")


def test_design_outside_box_is_accepted_when_said_so(tmp_path, paper_config, caplog):
    paper_config["checks"]["design_box"] = False
    path = _design(tmp_path, paper_config, DESIGN_FAULTS["outside-box"][0])
    assert load_study_design(path, paper_config)["m"][1] == 3.5
    assert "accepted: checks.design_box: false" in caplog.text


# ---- VISAR records ------------------------------------------------------------------------------

def _trace(n=400, step_us=0.0005):
    """A plausible record: 0.5 ns steps, at rest, then a 50 ns ramp to 200 m/s."""
    t = np.arange(n) * step_us
    return t, 200.0 * np.clip((t - t[n // 4]) / 0.05, 0.0, 1.0)


def _write(path, t, v, header="t_us,v_m_s"):
    path.write_text("\n".join([header, *(f"{float(a)!r},{float(b)!r}" for a, b in zip(t, v))]) + "\n")
    return path


def _record(tmp, kind):
    t, v = _trace()
    path = tmp / "record.csv"
    if kind == "km/s":
        return _write(path, t, v / 1000)
    if kind == "ns":
        return _write(path, t * 1000, v)
    if kind == "seconds":
        return _write(path, t * 1e-6, v)
    if kind == "binary":
        path.write_bytes(b"\x89PNG\r\n\x1a\n\x00\x00" + os.urandom(3000))
    elif kind == "ragged":
        _write(path, t, v).write_text(path.read_text() + "0.3,12.0,7\n")
    elif kind == "quote":
        _write(path, t, v).write_text(path.read_text().replace("\n0.001,", '\n"0.001,', 1))
    elif kind == "short":
        _write(path, t[:10], v[:10])
    elif kind == "nan":
        _write(path, t, np.where(np.arange(t.size) == 7, np.nan, v))
    elif kind == "time-not-increasing":
        _write(path, np.where(np.arange(t.size) == 9, t[8], t), v)
    elif kind == "columns-unnamed":
        _write(path, t, v, header="a,b")
    elif kind == "decimal-comma":
        path.write_text("% t (us)\tUp (m/s)\n" + "".join(f"{a:.4f}\t{b:.3f}\n".replace(".", ",") for a, b in zip(t, v)))
    elif kind == "cut-before-shock":        # noise about rest (0.3 m/s, as the paper's records), no rise
        _write(path, t, np.random.default_rng(1).normal(0.0, 0.3, t.size))
    elif kind == "one-column":
        path.write_text("v_m_s\n" + "".join(f"{b!r}\n" for b in v))
    elif kind == "empty":
        path.write_text("% only a comment\n")
    elif kind == "missing":
        path = tmp / "no-such-record.csv"
    else:
        _write(path, t, v)
    return path


RECORD_FAULTS = {
    "km/s": ["peak velocity = 0.2 m/s", "in km/s (0.2 km/s = 200 m/s)", OPT_OUT],
    "ns": ["duration = 199.5 us", "median time step = 0.5 us", "in ns (0.5 ns = 0.0005 us)", OPT_OUT],
    "seconds": ["median time step = 5e-10 us", "in s"],
    "binary": ["a binary file"],
    "ragged": ["line 402 has 3 fields, line 1 has 2"],
    "quote": ["not a readable table"],
    "short": ["10 points; at least 50 are needed"],
    "nan": ["1 non-numeric or NaN values (first at row 7)"],
    "time-not-increasing": ["time is not increasing at row 9"],
    "columns-unnamed": ["cannot tell which column is time among ['a', 'b']", "observed.records.<shot>.time_column"],
    "decimal-comma": ["line 401: '0,1995' has a decimal comma"],
    "empty": ["no data lines"],
    "missing": ["does not exist"],
    "cut-before-shock": ["no shock in it: up to its end at 0.1995 us its velocity stays below 10 m/s",
                         "the record ends before the shock arrives"],
    "one-column": ["one column ('v_m_s'); a record needs two, time (us) and velocity (m/s)"],
}


@pytest.mark.parametrize("fault", RECORD_FAULTS)
def test_record_faults(tmp_path, fault):
    path = _record(tmp_path, fault)
    with pytest.raises(InputError) as err:
        read_record(path)
    message = str(err.value)
    assert message.startswith(f"record {path}") and "\n" not in message
    for fragment in RECORD_FAULTS[fault]:
        assert fragment in message
    assert fault == "km/s" or "km/s" not in message                  # no unit slip suggested for a cut record


def test_record_named_column_that_is_absent(tmp_path):
    path = _record(tmp_path, "plausible")
    with pytest.raises(InputError, match=f"record {path}: no velocity column 'u'; columns are"):
        read_record(path, velocity_column="u")


def test_implausible_record_is_accepted_when_said_so(tmp_path, monkeypatch, caplog):
    monkeypatch.setenv(OPT_OUT, "1")
    t, v = read_record(_record(tmp_path, "km/s"))
    assert v.max() == pytest.approx(0.2, rel=1e-3)
    assert f"accepted: {OPT_OUT}=1" in caplog.text


# ---- observed features --------------------------------------------------------------------------

class StandInEmulator:
    """The emulator interface calibration needs before it samples."""

    feature_names = CALIBRATION_FEATURES

    def required_inputs(self, shots):
        return ["A"]

    def input_bounds(self, names):
        return np.array([0.0005]), np.array([0.01])

    def error_groups(self, shots):
        return [(np.arange(4 * len(shots)), ErrorModel())]


PUBLISHED_104S = {"t_jumpoff": 0.917, "v_jumpoff": 2.26, "t_elastic": 0.943, "v_elastic": 69.7, "t_plastic": 1.799,
                  "v_plastic": 199.8, "t_slope1": 1.006, "v_slope1": 81.5, "t_slope2": 1.163, "v_slope2": 187.8}


def _observed(**changes):
    row = {**PUBLISHED_104S, **changes}
    return pd.DataFrame([{"shot": "104S", "source": "test", **row}])


def _km_s(features):
    return {k: v / 1000 if k.startswith("v_") else v for k, v in features.items()}


OBSERVED_FAULTS = {
    "km/s": (_observed(**_km_s(PUBLISHED_104S)),
             ["shot 104S", "the largest velocity feature = 0.1998 m/s", "in km/s", "checks.observed_units: false"]),
    "times-in-ns": (_observed(**{k: v * 1000 for k, v in PUBLISHED_104S.items() if k.startswith("t_")}),
                    ["shot 104S", "the spread of the feature times = 882 us", "in ns"]),
    "negative": (_observed(v_slope1=-81.5), ["shot 104S", "['v_slope1'] missing or not positive"]),
    "nan": (_observed(v_elastic=np.nan), ["shot 104S", "['v_elastic'] missing or not positive"]),
    "missing-shot": (_observed().assign(shot="105S"), ["no observed features for shot 104S (have ['105S'])"]),
    "missing-column": (_observed().drop(columns="v_plastic"), ["missing column(s) ['v_plastic']"]),
}


@pytest.mark.parametrize("fault", OBSERVED_FAULTS)
def test_observed_table_faults(paper_config, fault):
    table, fragments = OBSERVED_FAULTS[fault]
    with pytest.raises(InputError) as err:
        calibrate(StandInEmulator(), ["104S"], table, calibration_settings(paper_config, ["104S"]),
                  source="obs.csv")
    for fragment in ["obs.csv", *fragments]:
        assert fragment in str(err.value)


@pytest.mark.parametrize("features, fragment", [
    (_km_s(PUBLISHED_104S), "the largest velocity feature = 0.1998 m/s"),
    ({k: v * 1e3 if k.startswith("t_") else v for k, v in PUBLISHED_104S.items()}, "the spread of the feature times = 882 us"),
])
def test_observed_features_in_config_are_checked(paper_config, features, fragment):
    paper_config["observed"]["features"]["104S"] = features
    with pytest.raises(ConfigError, match=f"config.yaml: observed.features.104S: {fragment}"):
        validate_config(paper_config, source="config.yaml")
    paper_config["checks"]["observed_units"] = False
    validate_config(paper_config, source="config.yaml")


# ---- configs and command lines ------------------------------------------------------------------

def _setting(config, path, value):
    *parents, last = path.split(".")
    node = config
    for key in parents:
        node = node[key]
    node[last] = value


@pytest.mark.parametrize("path, value, fragment", [
    ("hydro.cell_size_um", "four", "hydro.cell_size_um: 'four' is not of type 'number'"),
    ("simulate.chunk_size", 0, "simulate.chunk_size: 0 is less than the minimum of 1"),
    ("checks.design_box", "no", "checks.design_box: 'no' is not of type 'boolean'"),
    ("inputs.A.min", 0.02, "inputs.A.min: 0.02 is not below max (0.01)"),
    ("shots.105S.velocity_input", "V9", "shots.105S.velocity_input: 'V9' is not one of the inputs"),
    ("design.file", "no/such/design.csv", "design.file: no/such/design.csv does not exist"),
    ("calibration.replicates", 2, "calibration.replicates: 2 runs give no usable spread"),
])
def test_config_faults(paper_config, path, value, fragment):
    _setting(paper_config, path, value)
    with pytest.raises(ConfigError) as err:
        validate_config(paper_config, source="config.yaml")
    assert str(err.value).startswith("config.yaml: ") and fragment in str(err.value)


def test_config_file_faults(tmp_path):
    with pytest.raises(ConfigError, match=f"config file {tmp_path}/none.yaml does not exist"):
        load_config(tmp_path / "none.yaml")
    broken = tmp_path / "broken.yaml"
    broken.write_text("shots: [unclosed\n")
    with pytest.raises(ConfigError, match=f"config file {broken} is not valid YAML"):
        load_config(broken)


@pytest.mark.parametrize("overlay, fragment", [
    ({"simulate": {"chunk_size": 0}}, "{tmp}/overlay.yaml: simulate.chunk_size: 0 is less than the minimum of 1"),
    ("design-in-m/s", "{tmp}/overlay.yaml: design.file: {tmp}/design.csv: run 3: impact velocity V1 of shot 104S = 204 cm/us"),
])
def test_snakemake_prints_the_config_error_alone(tmp_path, paper_config, overlay, fragment):
    """One line, naming the file of the merged config (base, overlay or the overlay's overlay) that sets the key."""
    if overlay == "design-in-m/s":
        overlay = {"design": {"file": str(_design(tmp_path, paper_config, DESIGN_FAULTS["velocity-in-m/s"][0]))}}
    (tmp_path / "overlay.yaml").write_text(yaml.safe_dump(overlay))
    done = subprocess.run([str(Path(sys.executable).parent / "snakemake"), "--dry-run", "--configfile",
                           "config/quick.yaml", str(tmp_path / "overlay.yaml")], cwd=REPO, capture_output=True,
                          text=True)
    assert done.returncode != 0
    snakemake_notes = ("Using workflow specific profile", "Config file ")
    lines = [line for line in (done.stdout + done.stderr).splitlines() if not line.startswith(snakemake_notes)]
    assert len(lines) == 1, done.stdout + done.stderr
    assert lines[0].startswith("shockcal: error: " + fragment.format(tmp=tmp_path))


def test_command_line_faults():
    with pytest.raises(InputError, match="--features: '104S' is not SHOT=FILE"):
        parse_pairs(["104S"], "--features")
    with pytest.raises(InputError, match="--rows: '3-5' is not START:STOP"):
        parse_span("3-5", "--rows")
    failed = pd.DataFrame({"run": [0, 1, 2], "status": ["ok", "failed", "failed"], "reason": ["", "NaN", "NaN"]})
    with pytest.raises(ShockcalError, match=r"^shot 104S: 2 of 3 runs failed, .*the commonest reason, 2 runs: NaN "
                                            r"\(e\.g\. run 1: NaN\)$") as stopped:
        check_failures(failed, 0.05, "104S")
    assert "\n" not in str(stopped.value)


# ---- disks ----------------------------------------------------------------------------------------

DISK_FAULTS = {"full": (errno.ENOSPC, "No space left on device"), "read-only": (errno.EROFS, "Read-only file system"),
               "no-permission": (errno.EACCES, "Permission denied")}


@pytest.mark.parametrize("fault", DISK_FAULTS)
def test_disk_fault_is_one_line_and_leaves_nothing_that_looks_finished(tmp_path, monkeypatch, capsys, fault):
    import pyarrow.parquet as pq

    code, message = DISK_FAULTS[fault]
    real_write = pq.write_table

    def half_written(table, where, **kwargs):                 # half a file on disk, then the disk gives out
        real_write(table, where, **kwargs)
        Path(where).write_bytes(Path(where).read_bytes()[:100])
        raise OSError(code, message, str(where))

    monkeypatch.setattr(pq, "write_table", half_written)
    out = tmp_path / "results" / "design.parquet"
    rc = main(["design", "--config", str(REPO / "config" / "config.yaml"), "--out", str(out)])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2
    assert len(err) == 1 and err[0].startswith("shockcal design: error: ") and message in err[0], err
    assert list(out.parent.iterdir()) == [], "a half-written file was left behind"


def test_an_interrupted_write_keeps_the_finished_file(tmp_path):
    path = tmp_path / "table.parquet"
    write_table(pd.DataFrame({"run": [0, 1]}), path)
    with pytest.raises(KeyboardInterrupt), atomic_path(path) as tmp:
        tmp.write_bytes(b"PAR1 half")
        raise KeyboardInterrupt
    assert read_table(path)["run"].tolist() == [0, 1]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["table.parquet"]


def test_temporaries_of_a_killed_writer_are_swept(tmp_path):
    path = tmp_path / "chunk-0.parquet"
    (tmp_path / ".chunk-0.parquet.tmp-12345.parquet").write_bytes(b"PAR1 left by kill -9")
    write_table(pd.DataFrame({"run": [0]}), path)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["chunk-0.parquet"]


def test_truncated_chunk_is_named_with_the_way_out(tmp_path, capsys):
    chunk = tmp_path / "chunk-3.parquet"
    write_table(pd.DataFrame({"run": np.arange(50), "time_us": np.linspace(0, 1, 50)}), chunk)
    chunk.write_bytes(chunk.read_bytes()[:-40])                # a chunk cut short (disk full, copy interrupted)
    rc = main(["features", "--config", str(REPO / "config" / "config.yaml"), "--shot", "104S",
               "--traces", str(chunk), "--out", str(tmp_path / "features.parquet")])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and len(err) == 1, err
    assert f"table {chunk} could not be read" in err[0] and "delete it and rerun" in err[0]
    assert not (tmp_path / "features.parquet").exists()


# ==== the classes of fault, not the examples ======================================================
# Each message is one line (the CLI prints it alone) naming the file, key or shot; (a)-(c) name both
# sides of a conflict; (d) every reader survives damaged files; (e) inputs fine in substance read the
# same as the clean input.

def _one_line(err, *fragments):
    message = str(err.value)
    assert "\n" not in message, message
    for fragment in fragments:
        assert str(fragment) in message, (fragment, message)
    return message


def _small_emulator(config, directory=None):
    """A real 104S-only study emulator (20 runs of smooth made-up features on the paper's box), saved
    to `directory` when given."""
    from shockcal.emulator.input_map import shot_input_map
    from shockcal.emulator.pcgp import EmulatorSettings, PCGPEmulator
    from shockcal.emulator.study_emulator import Block, Emulator

    bounds = prior_bounds(config)
    mapping = shot_mapping(config, "104S")
    design = latin_hypercube({k: bounds[k] for k in mapping.inputs()}, 20, seed=3)
    input_map = shot_input_map(mapping, bounds)
    x = input_map.scaled(design)
    y = np.column_stack([60 + 20 * x[:, 0], 190 + 20 * x[:, 5], 80 + 10 * x[:, 1], 180 + 15 * x[:, 5] - 5 * x[:, 3]])
    model = PCGPEmulator.fit(input_map.raw(design), y, input_map.lower, input_map.upper,
                             EmulatorSettings(n_starts=1, cv_folds=3, calibrate_sd=False, n_jobs=1))
    emulator = Emulator("per_shot", [Block(input_map, ["104S"], design["run"].to_numpy(), model)], dict(bounds),
                        {"104S": mapping.inputs()})
    if directory is not None:
        emulator.save(directory)
    return emulator


@pytest.fixture(scope="module")
def small_emulator_dir(tmp_path_factory, paper_config_readonly):
    directory = tmp_path_factory.mktemp("emulator")
    _small_emulator(paper_config_readonly, directory)
    return directory


# ---- (a) conflicting or duplicated inputs --------------------------------------------------------

def _write_yaml_with_shot_twice(tmp):
    text = (REPO / "config" / "config.yaml").read_text()
    block = text[text.index("  106S:\n"):text.index("\n# Prior box")]
    path = tmp / "config.yaml"
    path.write_text(text.replace(block, block + "\n" + block.rstrip("\n").replace("window_after_arrival_us: 0.9",
                                                                                      "window_after_arrival_us: 0.8")))
    return path


def _features_twice(tmp):
    design = latin_hypercube(prior_bounds(_config()), 5, seed=1)
    table = _features_table(5).assign(run=[0, 1, 2, 2, 4])
    return lambda: training_data(design, table, "104S", "f.csv")


def _config():
    return load_config(REPO / "config" / "config.yaml")


DUPLICATE_FAULTS = {
    "observed-shot-twice": (lambda tmp: lambda: calibrate(
        StandInEmulator(), ["104S"], pd.concat([_observed(), _observed(v_plastic=201.0)]),
        calibration_settings(_config(), ["104S"]), source="obs.csv"),
        InputError, ["obs.csv", "shot 104S has 2 rows (rows [0, 1])", "one row per shot"]),
    "shots-twice": (lambda tmp: lambda: calibrate(StandInEmulator(), ["104S", "104S"], _observed(),
                                                  calibration_settings(_config(), ["104S"]), source="obs.csv"),
                    InputError, ["shots ['104S', '104S']: 104S listed more than once"]),
    "shot-twice-in-pairs": (lambda tmp: lambda: parse_pairs(["104S=a.parquet", "104S=b.parquet"], "--features"),
                            InputError, ["--features: shot 104S is given twice (104S=a.parquet and 104S=b.parquet)"]),
    "one-file-for-two-shots": (lambda tmp: lambda: parse_pairs(["104S=a.parquet", "105S=a.parquet"], "--features"),
                               InputError, ["--features: a.parquet is given for shots 104S and 105S"]),
    "config-key-twice": (lambda tmp: lambda: load_config(_write_yaml_with_shot_twice(tmp)),
                         ConfigError, ["config.yaml: shots.106S: given twice (lines", "YAML would keep only the last"]),
    "features-run-twice": (_features_twice, InputError, ["f.csv: run 2 appears more than once (rows [2, 3])"]),
    "chunk-run-twice": (lambda tmp: lambda: read_tables(
        [_save(_features_table(3), tmp / "c0.parquet"), _save(_features_table(3).assign(run=[3, 4, 4]),
                                                              tmp / "c1.parquet")], ["run"], "features"),
        InputError, ["c1.parquet: run 4 appears more than once in this features table"]),
    "chunks-overlap": (lambda tmp: lambda: read_tables(
        [_save(_features_table(3), tmp / "c0.parquet"), _save(_features_table(3).assign(run=[2, 3, 4]),
                                                              tmp / "c1.parquet")], ["run"], "features"),
        InputError, ["run 2 is in more than one features table", "c0.parquet", "c1.parquet"]),
}


def _save(frame, path):
    write_table(frame, path) if path.suffix == ".parquet" else frame.to_csv(path, index=False)
    return path


def _features_table(n):
    """A features table of `n` runs (ok, the published 104S features plus a little per run)."""
    rows = [{"run": i, "status": "ok", "reason": "", **{k: v + 0.5 * i for k, v in PUBLISHED_104S.items()}}
            for i in range(n)]
    return pd.DataFrame(rows)


@pytest.mark.parametrize("fault", DUPLICATE_FAULTS)
def test_duplicated_or_conflicting_inputs(tmp_path, fault):
    make, error, fragments = DUPLICATE_FAULTS[fault]
    with pytest.raises(error) as err:
        make(tmp_path)()
    _one_line(err, *fragments)


@pytest.mark.parametrize("change, fragment", [
    (lambda c: c["observed"]["records"]["105S"].update(path=c["observed"]["records"]["104S"]["path"]),
     "observed.records.105S.path: data/al5083/visar/Data_S104S.txt is also the record of shot 104S"),
    (lambda c: c["observed"]["features"].update({"105S": dict(c["observed"]["features"]["104S"])}),
     "observed.features.105S: the same values as observed.features.104S"),
])
def test_one_measurement_for_two_shots_in_the_config(paper_config, monkeypatch, change, fragment):
    monkeypatch.chdir(REPO)
    change(paper_config)
    with pytest.raises(ConfigError) as err:
        validate_config(paper_config, source="config.yaml")
    _one_line(err, "config.yaml: " + fragment)


def test_a_shot_twice_on_the_command_line_is_one_line(capsys, monkeypatch, tmp_path):
    monkeypatch.chdir(REPO)
    rc = main(["calibrate", "--config", "config/config.yaml", "--emulator", str(tmp_path), "--shots", "104S", "105S",
               "104S", "--observed", "obs.csv", "--out", str(tmp_path / "p.parquet")])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and err == ["shockcal calibrate: error: --shots: 104S given more than once (104S 105S 104S); "
                               "name each shot once"]


# ---- (b) an emulator or posterior outside what it was made for -----------------------------------

def _narrow(config, name, low=None, high=None):
    box = config["inputs"][name]
    box["min"] = box["min"] if low is None else low
    box["max"] = box["max"] if high is None else high
    return config


def _emulator_json(directory, tmp, change):
    import json
    import shutil

    target = tmp / "emulator"
    shutil.copytree(directory, target)
    meta = json.loads((target / "emulator.json").read_text())
    change(meta)
    (target / "emulator.json").write_text(json.dumps(meta))
    return target


MISUSE_FAULTS = {
    "box-wider-than-emulator's": (
        lambda em, tmp, c: lambda: Problem.for_shots(em, ["104S"], _observed(), 0.01, "obs.csv",
                                                     prior_bounds(_narrow(c, "V1", low=0.0185)), {"V1": "cm/us"}),
        ["calibration of 104S: the prior box inputs.V1 = [0.0185, 0.0216] cm/us is not inside the box the emulator was fitted on "
         "[0.0192, 0.0216] cm/us", "refit the emulator"]),
    "config-box-outside-emulator (emulator check)": (
        lambda em, tmp, c: lambda: em.check_study({}, prior_bounds(_narrow(c, "G1", high=0.6)), "emulator e/"),
        ["emulator e/: the prior box inputs.G1 = [0.2, 0.6] is not inside the box the emulator was fitted on [0.2, 0.5]"]),
    "shot-mapping-differs": (
        lambda em, tmp, c: lambda: em.check_study({"104S": ["A", "B", "C", "n", "m", "V2", "G1"]}, prior_bounds(c),
                                                  "emulator e/"),
        ["emulator e/: shot 104S reads the inputs ['A', 'B', 'C', 'n', 'm', 'V1', 'G1'] in the emulator and "
         "['A', 'B', 'C', 'n', 'm', 'V2', 'G1'] in the config (shots.104S)"]),
    "shot-not-fitted": (lambda em, tmp, c: lambda: em.required_inputs(["105S"]),
                        ["the emulator has no shot ['105S']; it was fitted for ['104S']"]),
    "design-outside-emulator's-box": (
        lambda em, tmp, c: lambda: em.check_inside(latin_hypercube(prior_bounds(c), 4, seed=2).pipe(_set, 2, "G1", 0.55),
                                                   "d.parquet"),
        ["d.parquet: run 2: G1 = 0.55 is outside the box the emulator was fitted on [0.2, 0.5]"]),
    "format-version": (
        lambda em, tmp, c: lambda: Emulator.load(_emulator_json(em.source, tmp, lambda m: m.update(version=0))),
        ["emulator.json: emulator format 'shockcal-emulator' version 0; this shockcal reads version"]),
    "features-of-another-extractor": (
        lambda em, tmp, c: lambda: Emulator.load(_emulator_json(em.source, tmp, lambda m: m.update(
            feature_names=["v_elastic", "v_plastic"]))),
        ["emulator.json: the emulator predicts features ['v_elastic', 'v_plastic']; this shockcal calibrates "
         "['v_elastic', 'v_plastic', 'v_slope1', 'v_slope2']"]),
    "posterior-outside-box": (
        lambda em, tmp, c: lambda: draw_posterior_design(
            latin_hypercube(prior_bounds(c), 8, seed=2).pipe(_set, 5, "m", 3.2), list(prior_bounds(c)), 4, 1,
            "joint.parquet", prior_bounds(c)),
        ["joint.parquet: row 5: m = 3.2 is outside the prior box inputs.m [0, 3]"]),
}


@pytest.mark.parametrize("fault", MISUSE_FAULTS)
def test_emulator_or_posterior_used_outside_what_it_was_made_for(tmp_path, paper_config, small_emulator_dir, fault):
    make, fragments = MISUSE_FAULTS[fault]
    emulator = Emulator.load(small_emulator_dir)
    with pytest.raises(InputError) as err:
        make(emulator, tmp_path, paper_config)()
    _one_line(err, *fragments)


def test_a_narrower_prior_box_is_calibrated_on(paper_config, small_emulator_dir):
    """The decision for a config box unlike the emulator's: inside it, the config's box is the prior."""
    emulator = Emulator.load(small_emulator_dir)
    _narrow(paper_config, "V1", low=0.0200, high=0.0210)
    problem = Problem.for_shots(emulator, ["104S"], _observed(), 0.01, "obs.csv", prior_bounds(paper_config))
    at = problem.names.index("V1")
    assert (problem.lower[at], problem.upper[at]) == (0.0200, 0.0210)
    assert problem.lower[problem.names.index("A")] == 0.0005
    emulator.check_study({"104S": shot_mapping(paper_config, "104S").inputs()}, prior_bounds(paper_config))


def test_a_single_shot_posterior_for_predict_is_one_line(tmp_path, paper_config, capsys, monkeypatch):
    monkeypatch.chdir(REPO)
    posterior = tmp_path / "104S.parquet"
    write_table(latin_hypercube(prior_bounds(paper_config), 8, seed=2).drop(columns="run"), posterior,
                {"table": "posterior samples", "shots": ["104S"]})
    rc = main(["predict", "--config", "config/config.yaml", "--posterior", str(posterior), "--out",
               str(tmp_path / "d.parquet")])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and len(err) == 1, err
    assert f"{posterior}: a posterior of shots ['104S']; predict draws from the joint posterior" in err[0]


# ---- (c) physical plausibility a unit check cannot see -------------------------------------------

def _swap_features(config):
    features = config["observed"]["features"]
    features["104S"], features["105S"] = features["105S"], features["104S"]


PLAUSIBILITY_FAULTS = {
    "features-of-two-shots-swapped": (
        _swap_features,
        ["observed.features.104S: the plastic plateau v_plastic = 351.7 m/s is outside [163.2, 226.8] m/s, "
         "0.85-1.05 x the shot's impact velocity box [192, 216] m/s", "checks.plateau_vs_velocity: false"]),
    "window-reaching-the-release": (
        lambda c: c["shots"]["104S"]["analysis"].update(window_after_arrival_us=1.3),
        ["shots.104S.analysis.window_after_arrival_us: 1.3 us reaches the release from the flyer's back, 1.27 us "
         "after the first arrival (first arrival 0.81 us after impact, release 2.08 us: flyer 3.95 mm, target "
         "5.965 mm, the box's largest shear modulus 50 GPa)"]),
    "window-of-a-thin-flyer": (
        lambda c: c["shots"]["106S"].update(flyer_mm=2.0),
        ["shots.106S.analysis.window_after_arrival_us: 0.9 us reaches the release", "flyer 2 mm"]),
}


@pytest.mark.parametrize("fault", PLAUSIBILITY_FAULTS)
def test_physically_implausible_configs(paper_config, fault):
    change, fragments = PLAUSIBILITY_FAULTS[fault]
    change(paper_config)
    with pytest.raises(ConfigError) as err:
        validate_config(paper_config, source="config.yaml")
    _one_line(err, "config.yaml: ", *fragments)


def test_plateau_check_opt_out(paper_config, caplog):
    _swap_features(paper_config)
    paper_config["checks"]["plateau_vs_velocity"] = False
    validate_config(paper_config, source="config.yaml")
    assert "accepted: checks.plateau_vs_velocity: false" in caplog.text


def test_observed_table_of_a_swapped_shot_is_refused_at_calibration(paper_config):
    table = _observed(**{**PUBLISHED_104S, "v_plastic": 359.0})
    with pytest.raises(InputError) as err:
        calibrate(StandInEmulator(), ["104S"], table, calibration_settings(paper_config, ["104S"]), source="obs.csv")
    _one_line(err, "obs.csv: shot 104S: the plastic plateau v_plastic = 359 m/s is outside [163.2, 226.8] m/s")


def test_records_of_two_shots_swapped_are_refused(paper_config, monkeypatch):
    from shockcal.study.adapters import observed_table

    monkeypatch.chdir(REPO)
    records = paper_config["observed"]["records"]
    records["104S"], records["105S"] = records["105S"], records["104S"]
    # the plateau check reads the extractor's features alone: without the read-out bootstrap (200 noise
    # replicates of the record, the bulk of the cost) the same features, the same refusal
    paper_config["observed"]["readout_error"] = False
    validate_config(paper_config, source="config.yaml")    # the files are fine; only their plateaus tell
    with pytest.raises(InputError) as err:
        observed_table(paper_config)
    _one_line(err, "shot 104S: record data/al5083/visar/Data_S105S.txt (observed.records.104S.path): the plastic "
                   "plateau v_plastic = 35", "impact velocity box [192, 216] m/s")


def test_release_times_follow_the_wave_paths():
    """flyer / c_bulk + (flyer + target) / c_L against the first arrival target / c_L (104S, G = 0.5 Mbar)."""
    from shockcal.plausibility import release_times_us

    c_bulk, c_l = np.sqrt(0.7797 / 2.668), np.sqrt(0.7797 / 2.668 + 4 * 0.5 / (3 * 2.668))
    arrival, release = release_times_us(3.95, 5.965, 2.668, 0.7797, 0.5)
    assert arrival == pytest.approx(0.5965 / c_l) and release == pytest.approx(0.395 / c_bulk + 0.9915 / c_l)
    assert 1.1 < release - arrival < 1.3     # the paper's 104S window (1.1 us) ends before it


# ---- (d) every file the project reads: damaged, empty, degenerate --------------------------------

def _design_frame(config):
    return latin_hypercube(prior_bounds(config), 5, seed=1)


def _posterior_frame(config):
    return latin_hypercube(prior_bounds(config), 8, seed=2).drop(columns="run").assign(lambda_y=1.0,
                                                                                      log_likelihood=-3.0)


def _chunk_frame(config):
    t, v = _trace(n=240)
    rows = [{"run": i, "shot": "104S", "status": "ok", "reason": "", "t_us": t, "v_m_s": v * (1 + 0.01 * i)}
            for i in range(2)]
    return pd.DataFrame(rows)


def _read_design(path, config):
    return load_study_design(path, config)


def _read_observed(path, config):
    return Problem.for_shots(StandInEmulator(), ["104S"], read_table(path), 0.01, str(path)).observed


def _read_posterior(path, config):
    return draw_posterior_design(read_table(path), list(prior_bounds(config)), 4, 1, str(path), prior_bounds(config))


def _read_chunk(path, config):
    from shockcal.velocimetry.feature_tables import features_table
    from shockcal.velocimetry.features import ExtractorSettings

    return features_table(read_table(path), ExtractorSettings(window_after_arrival_us=0.1, n_samples=300,
                                                              n_components=2), str(path))


def _read_features(path, config):
    return training_data(_design_frame(config), read_table(path), "104S", str(path))


READERS = {   # name: (clean frame, reader, id column)
    "design": (_design_frame, _read_design, "run"),
    "observed": (lambda c: _observed(), _read_observed, "shot"),
    "posterior": (_posterior_frame, _read_posterior, None),
    "chunk": (_chunk_frame, _read_chunk, "run"),
    "features": (lambda c: _features_table(5), _read_features, "run"),
}


def _assert_one_line_or_fine(read, path, config):
    """The reader returns, or stops with one ShockcalError line naming the file; never anything else."""
    try:
        read(path, config)
    except ShockcalError as exc:
        assert "\n" not in str(exc) and str(path.parent) in str(exc), str(exc)
        return "error"
    return "read"


@pytest.mark.parametrize("reader, suffix", [(reader, suffix) for reader in READERS for suffix in (".parquet", ".csv")
                                             if (reader, suffix) != ("chunk", ".csv")])   # chunks: Parquet only
def test_fuzz_cut_files(tmp_path, paper_config, reader, suffix):
    """Each table cut at 8 seeded offsets (and to nothing): one line naming the file, or a table read."""
    frame, read, _ = READERS[reader]
    clean = _save(frame(paper_config), tmp_path / f"clean{suffix}").read_bytes()
    outcomes = []
    for k, cut in enumerate([0, *np.random.default_rng(36).integers(1, len(clean), 8)]):
        path = tmp_path / f"cut-{k}{suffix}"
        path.write_bytes(clean[:cut])
        outcomes.append(_assert_one_line_or_fine(read, path, paper_config))
    if suffix == ".parquet":
        assert set(outcomes) == {"error"}, outcomes       # a cut Parquet file never reads


def _degenerate(frame, variant, id_column):
    if variant == "no-rows":
        return frame.iloc[:0]
    if variant == "one-row":
        return frame.iloc[:1]
    frame = frame.copy()
    frame[id_column] = frame[id_column].astype(object)
    frame.loc[1, id_column] = {"blank-id": None, "text-id": "x1", "fractional-id": 1.5}[variant]
    return frame


DEGENERATE = {   # (reader, variant): fragment of the error, or None: reads fine
    ("design", "no-rows"): "the design has no runs",
    ("design", "one-row"): None,
    ("design", "blank-id"): "row 1: run is blank; run ids are integers",
    ("design", "text-id"): "row 1: run = 'x1' is not a whole number",
    ("design", "fractional-id"): "row 1: run = 1.5 is not a whole number",
    ("observed", "no-rows"): "no observed features for shot 104S (have [])",
    ("observed", "one-row"): None,
    ("posterior", "no-rows"): "posterior has no samples",
    ("posterior", "one-row"): None,
    ("chunk", "no-rows"): "no runs (a simulations table with no rows)",
    ("chunk", "one-row"): None,
    ("chunk", "blank-id"): "row 1: run is blank",
    ("chunk", "text-id"): "row 1: run = 'x1' is not a whole number",
    ("chunk", "fractional-id"): "row 1: run = 1.5 is not a whole number",
    ("features", "no-rows"): "no runs (a features table with no rows)",
    ("features", "one-row"): None,
    ("features", "blank-id"): "row 1: run is blank",
    ("features", "text-id"): "row 1: run = 'x1' is not a whole number",
    ("features", "fractional-id"): "row 1: run = 1.5 is not a whole number",
}
WRONG_TYPES = {   # reader: (change to the clean frame, fragment)
    "design": (lambda f: f.assign(B=f["B"].astype(object)).pipe(_set, 4, "B", "high"),
               "run 4: parameter B is not a finite number ('high')"),
    "observed": (lambda f: f.assign(v_plastic="fast"), "shot 104S: observed feature(s) ['v_plastic'] missing"),
    "posterior": (lambda f: f.assign(A=f["A"].astype(object)).pipe(_set, 3, "A", "?"),
                  "row 3: A = '?' is not a finite number"),
    "chunk": (lambda f: f.assign(t_us=[str(list(t)) for t in f["t_us"]]),
              "run 0: t_us is str, not a list of numbers (simulation tables are Parquet"),
    "features": (lambda f: f.assign(v_slope1=f["v_slope1"].astype(object)).pipe(_set, 2, "v_slope1", "about 80"),
                 "row 2 (run 2): v_slope1 = 'about 80' is not a number"),
}


@pytest.mark.parametrize("reader, variant", [*DEGENERATE, *((r, "wrong-type") for r in WRONG_TYPES)])
def test_degenerate_tables(tmp_path, paper_config, reader, variant):
    frame, read, id_column = READERS[reader]
    suffix = ".parquet" if reader == "chunk" else ".csv"
    if variant == "wrong-type":
        change, fragment = WRONG_TYPES[reader]
        table = change(frame(paper_config))
    else:
        table, fragment = _degenerate(frame(paper_config), variant, id_column), DEGENERATE[reader, variant]
    if reader == "chunk" and variant in ("text-id", "blank-id"):
        table["run"] = table["run"].astype(str).where(table["run"].notna(), None)
    path = _save(table, tmp_path / f"{reader}{suffix}")
    if fragment is None:
        read(path, paper_config)
        return
    with pytest.raises(ShockcalError) as err:
        read(path, paper_config)
    _one_line(err, str(path), fragment)


@pytest.mark.parametrize("damage", ["json-cut", "json-empty", "json-not-an-object", "npz-cut", "npz-empty",
                                    "npz-array-missing", "json-block-missing"])
def test_damaged_emulator_directory(tmp_path, small_emulator_dir, damage):
    import json
    import shutil

    directory = tmp_path / "emulator"
    shutil.copytree(small_emulator_dir, directory)
    meta, npz = directory / "emulator.json", directory / "emulator.npz"
    if damage == "json-cut":
        meta.write_bytes(meta.read_bytes()[:int(np.random.default_rng(36).integers(1, meta.stat().st_size))])
    elif damage == "json-empty":
        meta.write_text("")
    elif damage == "json-not-an-object":
        meta.write_text("[1, 2]")
    elif damage == "npz-cut":
        npz.write_bytes(npz.read_bytes()[:int(np.random.default_rng(36).integers(1, npz.stat().st_size))])
    elif damage == "npz-empty":
        npz.write_bytes(b"")
    elif damage == "npz-array-missing":
        with np.load(npz) as arrays:
            kept = {k: arrays[k] for k in arrays.files if not k.endswith("/basis")}
        np.savez(npz, **kept)
    else:
        content = json.loads(meta.read_text())
        del content["blocks"][0]["hyperparameters"]
        meta.write_text(json.dumps(content))
    with pytest.raises(InputError) as err:
        Emulator.load(directory)
    _one_line(err, str(directory), "refit it with `shockcal emulate`")


@pytest.mark.parametrize("cut", [*np.random.default_rng(36).integers(5, 9000, 6).tolist()])
def test_fuzz_cut_records(tmp_path, cut):
    t, v = _trace()
    clean = _write(tmp_path / "clean.csv", t, v).read_bytes()
    path = tmp_path / "record.csv"
    path.write_bytes(clean[:cut])
    try:
        read_record(path)
    except InputError as exc:
        assert "\n" not in str(exc) and str(exc).startswith(f"record {path}")


# ---- (e) fine in substance: the same result as the clean input -----------------------------------

def _as_text(frame):
    return frame.to_csv(index=False)


FINE_VARIANTS = {
    "utf8-bom": lambda f: b"\xef\xbb\xbf" + _as_text(f).encode(),
    "utf16": lambda f: _as_text(f).encode("utf-16"),
    "crlf": lambda f: _as_text(f).replace("\n", "\r\n").encode(),
    "column-order": lambda f: _as_text(f[list(reversed(f.columns))]).encode(),
    "extra-column": lambda f: _as_text(f.assign(comment="from the lab book")).encode(),
    "ids-as-1.0": lambda f: _as_text(f.assign(run=f["run"].astype(float)) if "run" in f else f).encode(),
}


def _equal(a, b):
    if isinstance(a, pd.DataFrame):
        pd.testing.assert_frame_equal(a[sorted(a.columns)], b[sorted(b.columns)])
    else:
        np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize("variant", FINE_VARIANTS)
@pytest.mark.parametrize("reader", ["design", "observed", "posterior", "features"])
def test_fine_inputs_read_as_the_clean_one(tmp_path, paper_config, reader, variant):
    frame, read, _ = READERS[reader]
    clean = _save(frame(paper_config), tmp_path / "clean.csv")
    path = tmp_path / f"{variant}.csv"
    path.write_bytes(FINE_VARIANTS[variant](frame(paper_config)))
    result = read(path, paper_config)
    if reader == "features":        # training_data keeps the features table's extra columns out
        result = result.drop(columns="comment", errors="ignore")
    _equal(result, read(clean, paper_config))


@pytest.mark.parametrize("variant", ["utf8-bom", "utf16", "crlf", "columns-swapped"])
def test_fine_records_read_as_the_clean_one(tmp_path, variant):
    t, v = _trace()
    text = _write(tmp_path / "clean.csv", t, v).read_text()
    path = tmp_path / "variant.csv"
    if variant == "utf8-bom":
        path.write_bytes(b"\xef\xbb\xbf" + text.encode())
    elif variant == "utf16":
        path.write_bytes(text.encode("utf-16"))
    elif variant == "crlf":
        path.write_bytes(text.replace("\n", "\r\n").encode())
    else:
        path.write_text("\n".join(",".join(reversed(line.split(","))) for line in text.splitlines()) + "\n")
    for got, want in zip(read_record(path), read_record(tmp_path / "clean.csv")):
        np.testing.assert_array_equal(got, want)


def test_published_record_with_a_byte_order_mark_reads_as_released(tmp_path):
    """The paper's record as a Windows editor saves it (UTF-8 BOM, CRLF): the same arrays."""
    original = REPO / "data" / "al5083" / "visar" / "Data_S104S.txt"
    path = tmp_path / "Data_S104S.txt"
    path.write_bytes(b"\xef\xbb\xbf" + original.read_bytes().replace(b"\r\n", b"\n").replace(b"\n", b"\r\n"))
    for got, want in zip(read_record(path), read_record(original)):
        np.testing.assert_array_equal(got, want)
