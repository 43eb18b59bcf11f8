"""A calibration's posterior as an ArviZ `InferenceData` (netCDF), for ArviZ and any xarray reader.

`posterior_inference_data` takes plain tables and mappings (no study config) and returns the groups:

- `posterior`: the equal-weight draws, one chain: every calibrated input in the unit a user reads, that
  unit in its name and its `units` attribute (`A_MPa`, `B_MPa`, `G1_GPa`, `Delta2_GPa`, `V1_m_s`; C, n,
  m dimensionless), and lambda_y; coordinate `row`: the draw's row in the Parquet table; with
  `calibration.discrepancy`, its parameters (`delta_sd_fraction_<feature>`, `delta_rho_shots`:
  dimensionless, a `description` attribute each) and the sd they imply per shot in m/s,
  `delta_sd_<feature>_m_s` (chain, draw, shot): the fraction times the measured feature;
- `sample_stats`: `log_likelihood` of each draw (constants included);
- `observed_data`: the measured calibration features per shot (m/s), dims (`shot`,);
- `constant_data`: their sd (`<feature>_sd`, m/s) and the prior box `prior_lower`, `prior_upper` per
  `input` (the posterior's names and units), with its `unit` (a coordinate, and all units as the JSON
  attribute `units`);
- `posterior_predictive`, where given: the features of hydrocode runs at posterior draws (m/s), dims
  (chain, draw, shot), coordinate `run`;
- `weighted_posterior`: the sampler's weighted draws (the exact result): the parameters (as in
  `posterior`), `log_weight` (normalised, logsumexp = 0) and `log_likelihood`, dim `weighted_draw`.

The unit goes in the variable's name because `az.summary` and ArviZ's plots show names, not
attributes: a row reads `A_MPa  352.1  42.3 ...` (MPa, GPa and m/s put every value of the paper's
Table V at 3 significant figures or more, where its Mbar and cm/us read 0.004 and 0.000 at
`az.summary`'s 3 decimals). The Parquet tables keep the native units the design and the emulator use.

`weighted_posterior` is not one of ArviZ's standard groups; arviz 0.23.4 stores and reads it back
without a warning (`InferenceData(warn_on_custom_groups=False)`, its default), and ArviZ's functions
ignore it. The provenance (`attrs`: version, commit, config digest, sampler settings, log evidence)
goes on the file's root and on the `posterior` group.

The equal-weight draws are a systematic resample, written in the order of the weighted draws they
repeat; read as a chain, that order would make ArviZ's autocorrelation-based ESS meaningless (V2's
ess_bulk read 6 of 2000 on the quick study). They are stored in a fixed random order
(`numpy.random.default_rng(0)` permutation; `row` maps back). `az.summary`'s ess_bulk then reads about
the number of draws (1,760-2,050 of 2,000 on the quick study), which overstates what they hold: the
information is the weighted draws' Kish ESS, the attribute `ess_kish` (434 there). r_hat needs two
chains and reads NaN.
"""

from __future__ import annotations

import hashlib
import json
import subprocess
from collections.abc import Mapping
from pathlib import Path

import numpy as np
import pandas as pd

from shockcal.errors import InputError
from shockcal.inference.discrepancy import SD_FRACTION_PREFIX, SD_PREFIX, describe, is_discrepancy_parameter
from shockcal.inference.problem import LAMBDA_Y
from shockcal.io import atomic_path
from shockcal.units import user_columns
from shockcal.velocimetry.columns import CALIBRATION_FEATURES

WEIGHTED_GROUP = "weighted_posterior"


def git_commit(path: str | Path | None = None) -> str:
    """The short hash of the git checkout holding `path` (default: this package's source), "unknown"
    outside a checkout or without git."""
    where = Path(path) if path is not None else Path(__file__).resolve().parent
    try:
        done = subprocess.run(["git", "-C", str(where), "rev-parse", "--short", "HEAD"], capture_output=True,
                              text=True, timeout=10)
    except (OSError, subprocess.SubprocessError):
        return "unknown"
    return done.stdout.strip() if done.returncode == 0 and done.stdout.strip() else "unknown"


def config_digest(settings: Mapping) -> str:
    """sha256 (hex) of a config slice as JSON with sorted keys: equal slices, equal digests."""
    return hashlib.sha256(json.dumps(settings, sort_keys=True, default=str).encode()).hexdigest()


def _attribute(value):
    """A netCDF-storable attribute: numbers and strings as they are, anything else as JSON."""
    if isinstance(value, bool | np.bool_):
        return int(value)
    if isinstance(value, int | float | str | np.integer | np.floating):
        return value
    return json.dumps(value, sort_keys=True, default=str)


def posterior_inference_data(draws: pd.DataFrame, names: list[str], *, units: Mapping[str, str],
                             user_units: Mapping[str, str] | None = None,
                             lower: Mapping[str, float], upper: Mapping[str, float],
                             observed: pd.DataFrame, observed_sd: pd.DataFrame,
                             weighted: pd.DataFrame | None = None,
                             predictive: Mapping[str, pd.DataFrame] | None = None,
                             attrs: Mapping | None = None):
    """A posterior's `arviz.InferenceData` (groups in the module docstring).

    Args:
        draws: equal-weight draws: a column per name in `names` and `log_likelihood`.
        names: the parameters: the calibrated inputs (native units), then lambda_y (-) and the
            discrepancy's parameters (-), if any (`shockcal.inference.discrepancy`; no prior box).
        units: unit of each name in `draws` (e.g. "Mbar", "cm/us", "-").
        user_units: unit of each name in the file, where it differs from `units` (e.g. {"A": "MPa",
            "G1": "GPa", "V1": "m/s"}; `shockcal.units.user_unit`); the variable is named with it
            (`shockcal.units.unit_name`). None: the units of `units`, names with their units.
        lower, upper: the prior box of each calibrated input (its unit in `units`).
        observed: measured features, m/s: one row per shot (index: shot), one column per feature.
        observed_sd: their sd (m/s), the same shape.
        weighted: the sampler's weighted draws (the names, `log_weight`, `log_likelihood`), or None.
        predictive: shot -> features of the hydrocode runs at posterior draws (`run`, optional `status`,
            the feature columns in m/s); failed runs read as NaN. None or {}: no posterior_predictive group.
        attrs: provenance for the file's root and the posterior group (non-scalars stored as JSON).

    Returns:
        The `arviz.InferenceData`.
    """
    import arviz as az
    import xarray as xr

    missing = [c for c in [*names, "log_likelihood"] if c not in draws.columns]
    if missing:
        raise InputError(f"posterior draws: columns {missing} missing (columns: {list(draws.columns)})")
    inputs = [n for n in names if n != LAMBDA_Y and not is_discrepancy_parameter(n)]
    unboxed = [n for n in inputs if n not in lower or n not in upper]
    if unboxed:
        raise InputError(f"posterior draws: no prior box for inputs {unboxed}")
    features = list(observed.columns)
    if list(observed_sd.columns) != features or list(observed_sd.index) != list(observed.index):
        raise InputError("observed features and their sd differ in shots or features")
    attrs = {k: _attribute(v) for k, v in (attrs or {}).items()}
    shots = [str(s) for s in observed.index]
    n = len(draws)
    order = np.random.default_rng(0).permutation(n)      # see the module docstring: not a Markov chain
    draws = draws.iloc[order]
    columns = user_columns({name: units.get(name, "-") for name in names}, user_units or {})

    def variables(table, dims):
        """The parameters as variables along `dims` (one chain first, if any), keyed by their names with
        the user unit, in it."""
        shape = (1, -1) if dims[0] == "chain" else (-1,)
        return {columns[name][0]: (dims, table[name].to_numpy(float).reshape(shape) * columns[name][2],
                                   {"units": columns[name][1],
                                    **({"description": describe(name)} if is_discrepancy_parameter(name) else {})})
                for name in names}

    coords = {"chain": [0], "draw": np.arange(n), "row": (("draw",), order)}
    implied = _implied_sd(draws, names, observed)
    if implied:
        coords["shot"] = shots
    posterior = xr.Dataset({**variables(draws, ("chain", "draw")), **implied}, coords=coords, attrs=attrs)
    sample_stats = xr.Dataset({"log_likelihood": (("chain", "draw"), draws["log_likelihood"].to_numpy(float)[None, :])},
                              coords={"chain": [0], "draw": np.arange(n)})
    observed_data = xr.Dataset({f: (("shot",), observed[f].to_numpy(float), {"units": "m/s"}) for f in features},
                               coords={"shot": shots})
    constant = {f"{f}_sd": (("shot",), observed_sd[f].to_numpy(float), {"units": "m/s"}) for f in features}
    factors = np.array([columns[k][2] for k in inputs])
    constant["prior_lower"] = (("input",), np.array([lower[k] for k in inputs], float) * factors)
    constant["prior_upper"] = (("input",), np.array([upper[k] for k in inputs], float) * factors)
    constant_data = xr.Dataset(constant, coords={"shot": shots, "input": [columns[k][0] for k in inputs],
                                                 "unit": (("input",), [columns[k][1] for k in inputs])},
                               attrs={"units": _attribute({columns[k][0]: columns[k][1] for k in inputs})})
    groups = {"posterior": posterior, "sample_stats": sample_stats, "observed_data": observed_data,
              "constant_data": constant_data}
    if predictive:
        groups["posterior_predictive"] = _predictive(predictive, shots, features)
    if weighted is not None:
        missing = [c for c in [*names, "log_weight", "log_likelihood"] if c not in weighted.columns]
        if missing:
            raise InputError(f"weighted posterior draws: columns {missing} missing")
        groups[WEIGHTED_GROUP] = xr.Dataset(
            {**variables(weighted, ("weighted_draw",)),
             **{c: (("weighted_draw",), weighted[c].to_numpy(float)) for c in ("log_weight", "log_likelihood")}},
            coords={"weighted_draw": np.arange(len(weighted))},
            attrs={"about": "the sampler's weighted draws (the exact result); log_weight normalised, logsumexp = 0"})
    return az.InferenceData(attrs=attrs, **groups)


def _implied_sd(draws: pd.DataFrame, names: list[str], observed: pd.DataFrame) -> dict:
    """The discrepancy's sd in m/s per draw and shot, `delta_sd_<feature>_m_s` (chain, draw, shot): each
    sd fraction in `names` times the measured feature; {} without a discrepancy."""
    implied = {}
    for name in names:
        feature = name.removeprefix(SD_FRACTION_PREFIX)
        if name.startswith(SD_FRACTION_PREFIX) and feature in observed.columns:
            values = draws[name].to_numpy(float)[None, :, None] * np.abs(observed[feature].to_numpy(float))[None, None, :]
            implied[f"{SD_PREFIX}{feature}_m_s"] = (("chain", "draw", "shot"), values, {
                "units": "m/s", "description": f"model discrepancy's sd on {feature}: {name} times the measured {feature}"})
    return implied


def _predictive(predictive: Mapping[str, pd.DataFrame], shots: list[str], features: list[str]):
    """Features of the runs at posterior draws as (chain, draw, shot): draw = the run numbers of every
    shot's table (their union), NaN where a shot's run failed or is absent."""
    import xarray as xr

    given = [s for s in shots if s in predictive]
    runs = np.unique(np.concatenate([predictive[s]["run"].to_numpy() for s in given]))
    values = np.full((len(features), 1, len(runs), len(given)), np.nan)
    for j, shot in enumerate(given):
        table = predictive[shot]
        missing = [c for c in ["run", *features] if c not in table.columns]
        if missing:
            raise InputError(f"posterior-predictive features of {shot}: columns {missing} missing")
        if "status" in table.columns:
            table = table[table["status"].eq("ok")]
        rows = np.searchsorted(runs, table["run"].to_numpy())
        for i, feature in enumerate(features):
            values[i, 0, rows, j] = table[feature].to_numpy(float)
    return xr.Dataset({f: (("chain", "draw", "shot"), values[i], {"units": "m/s"}) for i, f in enumerate(features)},
                      coords={"chain": [0], "draw": np.arange(len(runs)), "run": (("draw",), runs), "shot": given},
                      attrs={"about": "features of hydrocode runs at joint-posterior draws (run set 'predict')"})


def observed_frames(shots: list[str], observed: list[float], observed_sd: list[float],
                    features: list[str] = CALIBRATION_FEATURES) -> tuple[pd.DataFrame, pd.DataFrame]:
    """A calibration's measured vector and sd (shot-major, `features` per shot; m/s) as two tables
    indexed by shot."""
    k = len(features)
    if len(observed) != k * len(shots) or len(observed_sd) != len(observed):
        raise InputError(f"observed vector of {len(observed)} values (sd: {len(observed_sd)}) for {len(shots)} "
                         f"shots of {k} features")
    shape = (len(shots), k)
    index = pd.Index(shots, name="shot")
    return (pd.DataFrame(np.reshape(observed, shape), index=index, columns=features),
            pd.DataFrame(np.reshape(observed_sd, shape), index=index, columns=features))


def write_inference_data(idata, path: str | Path) -> Path:
    """Write `idata` to netCDF (h5netcdf engine) at `path`, atomically."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_path(path) as tmp:
        idata.to_netcdf(str(tmp), engine="h5netcdf")
    return path
