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

from shockcal.calibration import calibrate
from shockcal.cli import main, parse_pairs, parse_span
from shockcal.design import latin_hypercube
from shockcal.error_model import ErrorModel
from shockcal.errors import ConfigError, InputError, ShockcalError
from shockcal.features import check_failures
from shockcal.io import atomic_path, read_table, write_table
from shockcal.records import OPT_OUT, read_record
from shockcal.study.adapters import calibration_settings, load_study_design, shot_mapping
from shockcal.study.config import prior_bounds
from shockcal.study.validate import load_config, validate_config

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
    "nan": (lambda d: _set(d, 2, "A", np.nan), ["run 2: parameter A is not a finite number"]),
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
    with pytest.raises(InputError, match="d.csv: run 0: impact velocity V2 = 0.0 must be positive for shot 105S"):
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
    ("inputs.A.min", 0.02, "inputs.A: min (0.02) must be below max"),
    ("shots.105S.velocity_input", "V9", "shots.105S.velocity_input: 'V9' is not one of the inputs"),
    ("design.file", "no/such/design.csv", "design.file: no/such/design.csv does not exist"),
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
    ({"simulate": {"chunk_size": 0}}, "config: simulate.chunk_size: 0 is less than the minimum of 1"),
    ("design-in-m/s", "config: design.file: {tmp}/design.csv: run 3: impact velocity V1 of shot 104S = 204 cm/us"),
])
def test_snakemake_prints_the_config_error_alone(tmp_path, paper_config, overlay, fragment):
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
    with pytest.raises(ShockcalError, match=r"shot 104S: 2 of 3 runs failed.*\n  run 1: NaN"):
        check_failures(failed, 0.05, "104S")


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
