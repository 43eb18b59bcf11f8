"""Feature extractor (SPEC section 4) on traces with known answers, record reading, the features table,
and the measured records (shipped in data/al5083) against the published features."""

import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from scipy.stats import norm

from shockcal.errors import InputError
from shockcal.study.adapters import extractor_settings
from shockcal.velocimetry.columns import COLUMNS
from shockcal.velocimetry.feature_tables import features_table, record_features
from shockcal.velocimetry.features import (
    Mixture,
    extract,
    extract_features,
    feature_times,
    feature_values,
    fit_mixture,
    fit_mixture_exact,
    split_early,
)
from shockcal.velocimetry.mixture_fit import fit_piecewise_linear_cdf
from shockcal.velocimetry.records import read_record

DATA = Path(__file__).resolve().parents[1] / "data" / "al5083"   # the shipped records and published features

# Two-step trace: v(t) = V1 Phi((t - T1)/S1) + V2 Phi((t - T2)/S2) (m/s, us), on the 0.5 ns grid of a
# 4 us run, flat (the baseline) before the first rise. The CDF the extractor reads is then exactly
# a mixture of two Gaussians: the early one with weight V1/(V1+V2), the late one with V2/(V1+V2).
T1, S1, V1 = 1.0, 0.005, 70.0
T2, S2, V2 = 1.25, 0.04, 130.0
T = np.arange(8001) * 0.0005
SHOT = "104S"  # its window (1.1 us after arrival) ends after both rises; its cut-off falls between them
N_SAMPLES = 10000
N_EARLY, N_LATE = N_SAMPLES * V1 / (V1 + V2), N_SAMPLES * V2 / (V1 + V2)


def curve(t):
    return V1 * norm.cdf((t - T1) / S1) + V2 * norm.cdf((t - T2) / S2)


def slope(t):
    return V1 * norm.pdf((t - T1) / S1) / S1 + V2 * norm.pdf((t - T2) / S2) / S2


def trace(offset=0.0, noise_sd=0.0, noise_seed=0):
    return curve(T) + offset + np.random.default_rng(noise_seed).normal(0.0, noise_sd, T.size)


def quantile_tolerance(sd, p, n):
    """5 sampling sd of the p quantile of a Gaussian fitted to n samples: 5 sd sqrt((1 + z^2/2) / n)."""
    z = norm.ppf(p)
    return 5 * sd * np.sqrt((1 + z * z / 2) / n)


# Exact answers of the construction (time us, velocity m/s, time tolerance us). The GMM features are
# quantiles of one Gaussian estimated from its share of the 10,000 PIT samples: 5 sampling sd
# (0.81 ns for jump-off/elastic, 3.3 ns for the slope points) cannot fail by chance, while a wrong
# quantile level (e.g. 0.05 for 0.1: 15 ns) or a wrong component split (tens of ns) is caught.
# Velocity tolerances are the curve's slope times the time tolerance (0.30 and 1.9 m/s).
EXPECTED = {
    "jumpoff": (T1 + S1 * norm.ppf(0.01), 0.01 * V1, quantile_tolerance(S1, 0.01, N_EARLY)),
    "elastic": (T1 + S1 * norm.ppf(0.99), 0.99 * V1, quantile_tolerance(S1, 0.99, N_EARLY)),
    "slope1": (T2 + S2 * norm.ppf(0.1), V1 + 0.1 * V2, quantile_tolerance(S2, 0.1, N_LATE)),
    "slope2": (T2 + S2 * norm.ppf(0.9), V1 + 0.9 * V2, quantile_tolerance(S2, 0.9, N_LATE)),
}
# Plastic plateau: the standardized trace is v / (V1 + V2), so it reaches 0.995 where the late step
# reaches 1 - 0.005 (V1 + V2) / V2; the feature is the first grid point at or after that time.
T_PLASTIC = T2 + S2 * norm.ppf(1 - 0.005 * (V1 + V2) / V2)
GRID_STEP = 0.0005


@pytest.fixture
def settings(paper_config):
    return extractor_settings(paper_config, SHOT)


def features(v, settings):
    return extract_features(T, v, settings)


def test_known_answers_of_a_two_step_trace(settings):
    f = features(trace(), settings)
    for name, (t_expected, v_expected, t_tol) in EXPECTED.items():
        assert f[f"t_{name}"] == pytest.approx(t_expected, abs=t_tol), name
        assert f[f"v_{name}"] == pytest.approx(v_expected, abs=slope(t_expected) * t_tol), name
    assert 0 <= f["t_plastic"] - T_PLASTIC <= GRID_STEP
    assert 0.995 * (V1 + V2) <= f["v_plastic"] <= 0.995 * (V1 + V2) + slope(T_PLASTIC) * GRID_STEP
    # the slope points lie on the curve (linear interpolation error < 1e-3 m/s) between the plateaus
    for name in ("slope1", "slope2"):
        assert f[f"v_{name}"] == pytest.approx(curve(f[f"t_{name}"]), abs=1e-3)
    assert f["t_elastic"] < f["t_slope1"] < f["t_slope2"] < f["t_plastic"]
    assert f["v_elastic"] < f["v_slope1"] < f["v_slope2"] < f["v_plastic"]


def test_a_weak_precursor_of_a_trace_at_rest_is_the_arrival(paper_config):
    """Small A or m near 0 (106S): a 6 m/s precursor 0.1 us ahead of a 470 m/s plastic wave, below
    the 2% arrival level a noisy record needs. A trace exactly at rest before it (a simulation)
    takes the precursor as the arrival, so the elastic plateau is the precursor, not the wave."""
    v = 6.0 * norm.cdf((T - 0.90) / 0.004) + 464.0 * norm.cdf((T - 1.00) / 0.01)
    f = extract_features(T, v, extractor_settings(paper_config, "106S"))
    assert f["t_jumpoff"] == pytest.approx(0.90 + 0.004 * norm.ppf(0.01), abs=1e-3)
    assert f["v_elastic"] == pytest.approx(6.0 * 0.99, abs=0.1)
    assert f["v_plastic"] > 460


def test_a_single_wave_still_has_ordered_features(settings):
    """Large A in 104S: the elastic wave is the whole rise (no plastic wave behind it)."""
    v = 200.0 * norm.cdf((T - 0.92) / 0.006)
    f = features(v, settings)
    assert f["t_jumpoff"] < f["t_elastic"] <= f["t_plastic"]
    assert f["t_slope1"] < f["t_slope2"]
    assert f["v_slope2"] <= f["v_plastic"] <= 200.0 and f["v_plastic"] >= 0.99 * 200.0
    assert f["t_elastic"] <= f["t_slope1"] and f["v_elastic"] <= f["v_slope1"]   # on the top, as FLAG's
    assert f["v_elastic"] >= 0.9 * 200.0


def test_a_precursor_without_a_component_of_its_own_is_read_inside_the_elastic_part():
    # A 7 m/s precursor 0.25 us ahead of a 460 m/s plastic wave (A near 50 MPa in 106S). When EM
    # gives the precursor no component before the cut-off, the early stand-in is the broad earliest
    # component: its 0.99 quantile lay on the plastic plateau (v_elastic = v_plastic, design run 106
    # of the study) and its 0.01 quantile before the window. They are kept in [window start, cut-off].
    v = 7.0 * norm.cdf((T - 1.0) / 0.003) + 460.0 * norm.cdf((T - 1.25) / 0.003)
    window = (T >= 0.95) & (T <= 1.9)
    cdf = (v[window] - v[window].min()) / np.ptp(v[window])
    mixture = Mixture(np.array([0.02, 0.49, 0.49]), np.array([1.1, 1.249, 1.251]), np.array([0.15, 0.002, 0.002]))
    cutoff = 1.04
    early = split_early(mixture, cutoff)
    assert early.tolist() == [True, False, False]      # the fallback: no component ends before the cut-off
    features = feature_values(T, v, feature_times(T[window], cdf, mixture, early, cutoff))
    assert features["t_elastic"] == cutoff and features["v_elastic"] == pytest.approx(7.0, abs=0.01)
    assert features["t_jumpoff"] == pytest.approx(0.95)
    assert 7.0 < features["v_slope1"] < features["v_slope2"] < 467.0


@pytest.mark.parametrize("noise_sd", [0.0, 1.0])
def test_features_are_a_deterministic_and_stable_function_of_the_trace(settings, noise_sd):
    """No seed: the same trace gives the same features bit for bit, and the trace perturbed at 1e-6 of
    its rise gives the same features within 0.01 m/s and 0.01 ns (EM converged from fixed starts; the
    seeded extractor this replaced moved them by up to 28 m/s or ns on hydrocode traces)."""
    v = trace(noise_sd=noise_sd)
    first, again = features(v, settings), features(v, settings)
    assert first == again
    perturbed = features(v + 1e-6 * (V1 + V2) * np.random.default_rng(7).standard_normal(T.size), settings)
    for column in COLUMNS:
        scale = 1e3 if column.startswith("t_") else 1.0                # ns or m/s
        assert abs(perturbed[column] - first[column]) * scale < 1e-2, column


def test_neighbouring_hydrocode_runs_have_neighbouring_features(paper_config):
    """106S at C near 0 (where the old seeded extractor moved v_slope1 by 6 m/s between near-identical
    runs): two runs 1e-4 apart in C give slope velocities within 0.5 m/s."""
    from shockcal.hydro import ShotParameters, run_shot
    from shockcal.study.adapters import hydro_inputs

    paper_config["hydro"]["end_time_us"] = 2.1
    shot = paper_config["shots"]["106S"]
    runs = [run_shot(ShotParameters.from_table_iv(0.0035, 0.004, C, 0.3, 1.0, 0.0484, 0.33), *hydro_inputs(paper_config, shot))
            for C in (0.0010, 0.0011)]
    settings = extractor_settings(paper_config, "106S")
    first, second = (extract_features(r.t_us, r.v_m_s, settings) for r in runs)
    for column in ("v_elastic", "v_slope1", "v_slope2", "v_plastic"):
        assert abs(first[column] - second[column]) < 0.5, column


@pytest.mark.parametrize("offset", [-3.0, 5.0])
def test_baseline_offset_moves_velocities_by_the_offset_only(settings, offset):
    v = trace(noise_sd=1.0)
    plain, shifted = features(v, settings), features(v + offset, settings)
    for column in COLUMNS:
        expected = plain[column] + (offset if column.startswith("v_") else 0.0)
        assert shifted[column] == pytest.approx(expected, abs=1e-9), column


NOISE_REALIZATIONS = 10


@pytest.mark.parametrize("plateau, robust", [
    ("elastic", None), ("plastic", None), ("elastic", False),
    pytest.param("plastic", False, marks=pytest.mark.xfail(strict=True, reason=(
        "the running maximum (the read before 2026-11-26): v_plastic moves +3.8 m/s on average (3.1 to 4.4) "
        "under 1 m/s white noise, measured: the window's max is a noise peak, so the 0.995 crossing is read "
        "on a noise excursion"))),
])
def test_noise_moves_plateaus_by_at_most_two_m_s(settings, plateau, robust):
    """1 m/s seeded Gaussian noise: the mean shift of a plateau velocity over 10 realizations, read
    robustly (a noisy trace's default: isotonic fit, local linear reads) or as a noise-free trace.

    Each velocity is one noisy sample (sd 1 m/s), so the mean of 10 has sd 0.32 m/s: a shift above
    2 m/s is the extractor's, not the draw's.
    """
    clean = features(trace(), settings)[f"v_{plateau}"]
    shifts = [extract(T, trace(noise_sd=1.0, noise_seed=k), settings, robust=robust).features[f"v_{plateau}"] - clean
              for k in range(NOISE_REALIZATIONS)]
    assert abs(np.mean(shifts)) <= 2.0


def write_trace(path, header, table, sep=","):
    path.write_text("\n".join([*header, *(sep.join(str(x) for x in row) for row in table)]) + "\n")
    return path


def test_read_record_csv_detects_or_takes_the_named_columns(tmp_path):
    t, v = T[:200], curve(T[:200] + 0.95)
    path = tmp_path / "trace.csv"
    pd.DataFrame({"run": 0, "v_m_s": v, "t_us": t}).to_csv(path, index=False)
    for columns in [(None, None), ("t_us", "v_m_s"), (2, 1)]:
        t_read, v_read = read_record(path, *columns)
        np.testing.assert_array_equal(t_read, t)
        np.testing.assert_array_equal(v_read, v)


def test_read_record_whitespace_with_percent_header(tmp_path):
    """As in the released VISAR files: '%' comments, the last one naming the columns (velocity first)."""
    t, v = T[:100], curve(T[:100] + 0.95)
    path = write_trace(tmp_path / "Data_S999S.txt", ["%Wave profile data for shot S999S", "% Up (m/s)  t (us)"],
                       zip(v, t), sep="\t")
    t_read, v_read = read_record(path)
    np.testing.assert_array_equal(t_read, t)
    np.testing.assert_array_equal(v_read, v)


def rows(n=60):
    return [[i * 0.0005, float(i)] for i in range(n)]


def broken_rows(case):
    table = rows()
    if case == "nan":
        table[5][1] = "nan"
    elif case == "time":
        table[7][0] = table[6][0]
    return table


@pytest.mark.parametrize("case, columns, problem", [
    ("short", (None, None), "10 points; at least 50 are needed"),
    ("nan", (None, None), r"1 non-numeric or NaN values \(first at row 5\)"),
    ("time", (None, None), "time is not increasing at row 7"),
    ("ok", ("time_s", None), r"no time column 'time_s'; columns are \['t \(us\)', 'v \(m/s\)'\]"),
    ("ok", (None, 5), "no velocity column 5"),
])
def test_record_errors_name_the_file_and_the_problem(tmp_path, case, columns, problem):
    path = write_trace(tmp_path / "rec.csv", ["t (us),v (m/s)"], rows(10) if case == "short" else broken_rows(case))
    with pytest.raises(InputError, match=re.escape(f"record {path}: ") + problem):
        read_record(path, *columns)


def test_record_with_unnamed_columns_asks_for_names(tmp_path):
    path = write_trace(tmp_path / "rec.csv", ["a,b"], rows())
    with pytest.raises(InputError, match=re.escape(f"record {path}: cannot tell which column is time")):
        read_record(path)


def test_record_without_a_rise_names_the_file(tmp_path, paper_config):
    """A flat record is stopped as it is read: it ends before the shock (tests/test_faults.py, "cut-before-shock")."""
    path = write_trace(tmp_path / "flat.csv", ["t_us,v_m_s"], [[t, 1.5] for t in T])
    with pytest.raises(InputError, match=re.escape(f"record {path}: no shock in it: up to its end at 4 us its velocity "
                                                   "is 1.5 m/s throughout: the record ends before the shock arrives")):
        record_features(path, extractor_settings(paper_config, SHOT), SHOT)


def test_features_table_marks_unreadable_traces_failed_and_goes_on(paper_config):
    broken = np.full(T.size, np.nan)
    broken[:10] = 0.0
    traces = pd.DataFrame({
        "run": [3, 0, 1, 2, 4],
        "status": ["ok", "ok", "ok", "ok", "failed"],
        "reason": ["", "", "", "", "hydro: energy error 0.2"],
        "t_us": [T, T, T, T, np.array([])],
        "v_m_s": [trace(noise_sd=1.0), trace(), np.zeros(T.size), broken, np.array([])],
    })
    settings = extractor_settings(paper_config, SHOT)
    table = features_table(traces, settings)
    assert list(table.columns) == ["run", "status", "reason", *COLUMNS]
    assert table["run"].tolist() == [0, 1, 2, 3, 4]
    assert table["status"].tolist() == ["ok", "failed", "failed", "ok", "failed"]
    assert table["reason"][1].startswith("feature extraction: no rise above the baseline")
    assert table["reason"][2] == f"feature extraction: {T.size - 10} non-finite values in the trace (first at index 10)"
    assert table["reason"][4] == "hydro: energy error 0.2"
    assert table.loc[table["status"] == "ok", COLUMNS].notna().all().all()
    assert table.loc[table["status"] != "ok", COLUMNS].isna().all().all()
    # a run's features do not depend on its position in the batch
    expected = extract_features(T, trace(noise_sd=1.0), settings)
    assert table.loc[3, COLUMNS].to_dict() == expected


# Measured records against the features published with the paper (observed_features.csv, the paper's
# own extractor). Bounds are just above the measured differences where those are within the accepted
# worst case (3 m/s, 10 ns); t_plastic is not compared (the 0.995 crossing of a slowly rising noisy
# plateau: -262, +86 and +302 ns with the isotonic fit). Cases beyond the worst case keep that bound and
# are xfail with the measured difference. Read robustly (isotonic fit, local linear reads over the
# record's noise window, 2026-11-26), jump-off and elastic times agree within 0.9 ns in every shot.
WORST_CASE = (3.0, 0.010)  # m/s, us
BOUNDS = {"104S": (2.4, 0.0075), "105S": (2.4, 0.0025), "106S": (2.2, 0.0030)}
BEYOND = {  # measured (ours - published), m/s
    ("105S", "v_plastic"): 4.76, ("106S", "v_elastic"): -3.28,
}


def record_cases():
    for shot in BOUNDS:
        for column in COLUMNS:
            if column == "t_plastic":
                continue
            if (shot, column) in BEYOND:
                unit = "ns" if column.startswith("t_") else "m/s"
                reason = f"{shot} {column}: measured {BEYOND[shot, column]:+} {unit}, beyond the worst case"
                yield pytest.param(shot, column, marks=pytest.mark.xfail(strict=True, reason=reason))
            else:
                yield pytest.param(shot, column)


@pytest.fixture(scope="module")
def record_differences(paper_config_readonly):
    published = pd.read_csv(DATA / "observed_features.csv").set_index("shot")
    return {shot: {column: value - published.loc[shot, column]
                   for column, value in record_features(DATA / "visar" / f"Data_S{shot}.txt",
                                                        extractor_settings(paper_config_readonly, shot),
                                                        shot).items() if column in COLUMNS}
            for shot in BOUNDS}


@pytest.mark.parametrize("shot, column", list(record_cases()))
def test_measured_record_matches_published_features(record_differences, shot, column):
    velocity_bound, time_bound = WORST_CASE if (shot, column) in BEYOND else BOUNDS[shot]
    bound = time_bound if column.startswith("t_") else velocity_bound
    assert abs(record_differences[shot][column]) <= bound


# The exact fit (shockcal.velocimetry.mixture_fit): EM on the piecewise-linear CDF itself, the limit of infinitely
# many PIT samples. A trace that is exactly a two-Gaussian CDF (window 0.9-1.6 us, 0.5 ns grid) is
# read by the extractor as the piecewise-linear interpolation of that CDF, whose components are the
# Gaussians' with each variance raised by at most h^2/6 (h = 0.5 ns: the uniform spread inside the
# grid steps, and Sheppard's h^2/12 of the steps' midpoints). Measured: weights within 7e-11, means
# within 3e-11 us, sds +5.7e-6 and +7e-7 us; a 100,000-sample PIT fit lies within 1e-6 us of it.
TRUE_WEIGHTS, TRUE_MEANS, TRUE_SDS = np.array([0.35, 0.65]), np.array([1.0, 1.25]), np.array([0.005, 0.04])
GRID = np.arange(0.9, 1.6, 0.0005)


def two_gaussian_cdf():
    cdf = (TRUE_WEIGHTS * norm.cdf((GRID[:, None] - TRUE_MEANS) / TRUE_SDS)).sum(axis=1)
    return (cdf - cdf[0]) / (cdf[-1] - cdf[0])


def test_exact_fit_recovers_a_known_two_component_mixture_and_agrees_with_many_pit_samples():
    y = two_gaussian_cdf()
    n = 100_000
    rising = np.diff(y, prepend=-1.0) > 0
    samples = np.interp((np.arange(n) + 0.5) / n, y[rising], GRID[rising])
    exact = fit_mixture_exact(GRID, y, samples, 2)
    order = np.argsort(exact.means)
    np.testing.assert_allclose(exact.weights[order], TRUE_WEIGHTS, atol=1e-8)
    np.testing.assert_allclose(exact.means[order], TRUE_MEANS, atol=1e-8)
    inflation = exact.sds[order] - TRUE_SDS
    assert np.all(inflation >= 0) and np.all(inflation <= 0.0005**2 / (6 * TRUE_SDS)), inflation
    pit = fit_mixture(samples, 2)
    pit_order = np.argsort(pit.means)
    np.testing.assert_allclose(exact.weights[order], pit.weights[pit_order], atol=1e-6)
    np.testing.assert_allclose(exact.means[order], pit.means[pit_order], atol=1e-6)
    np.testing.assert_allclose(exact.sds[order], pit.sds[pit_order], atol=1e-6)


def test_exact_fit_is_deterministic_and_squarem_reaches_plain_em_optimum(settings):
    """The same trace twice gives identical mixtures and features. SQUAREM (the default) and plain EM,
    run to a tight tolerance, reach the same optimum of two overlapping Gaussians (EM's slow case:
    measured 3,700 against 9,500 EM steps over the three starts, log-likelihood higher by 2e-10)."""
    first, again = extract(T, trace(), settings), extract(T, trace(), settings)
    assert first.features == again.features
    for name in ("weights", "means", "sds"):
        np.testing.assert_array_equal(getattr(first.mixture, name), getattr(again.mixture, name))
    cdf = 0.4 * norm.cdf((GRID - 1.0) / 0.02) + 0.6 * norm.cdf((GRID - 1.03) / 0.03)
    fits = [fit_piecewise_linear_cdf(GRID, (cdf - cdf[0]) / (cdf[-1] - cdf[0]), 2, 3, 1e-12, 100_000,
                                     accelerate=accelerate)
            for accelerate in (True, False)]
    (fast, fast_info), (plain, plain_info) = fits
    for a, b in zip(fast, plain):      # the likelihood is flat here: plain EM still creeps at 1e-12 a step
        np.testing.assert_allclose(a, b, rtol=1e-3)
    assert max(run[0] for run in fast_info["runs"]) >= max(run[0] for run in plain_info["runs"])
    assert sum(run[1] for run in fast_info["runs"]) < sum(run[1] for run in plain_info["runs"]) / 2


def test_pit_reference_path_is_kept_and_unknown_fits_are_refused(settings):
    exact, pit = extract(T, trace(), settings), extract(T, trace(), settings, method="pit")
    assert exact.samples.size == pit.samples.size == settings.n_samples   # the figures' samples
    for column in COLUMNS:
        scale = 1e3 if column.startswith("t_") else 1.0
        assert abs(exact.features[column] - pit.features[column]) * scale < 1.0, column
    with pytest.raises(ValueError, match="unknown mixture fit"):
        extract(T, trace(), settings, method="em")


def test_slope_times_stay_inside_the_window_when_the_late_mixture_is_one_broad_component():
    """A single-wave trace (large A) can leave EM one broad component of a few 1e-5 of the mass spread
    over the plateau; its 0.9 quantile lies past the window, where the release has come: the slope times
    are read at the window's end instead (the study's 104S runs 349 and 748 read v_slope2 = 0.001 m/s)."""
    from shockcal.velocimetry.features import Mixture, feature_times, feature_values

    t = np.linspace(0.0, 2.4, 4801)
    v = np.where(t < 0.88, 0.0, 213.0) * (t < 2.2)           # one wave, then the release at 2.2 us
    t_window = t[(t >= 0.83) & (t <= 1.97)]
    cdf = np.clip((t_window - 0.83) / 0.06, 0.0, 1.0)
    mixture = Mixture(np.array([0.6, 0.39993, 7e-5]), np.array([0.882, 0.885, 1.76]), np.array([0.004, 0.003, 0.41]))
    early = np.array([True, True, False])
    features = feature_values(t, v, feature_times(t_window, cdf, mixture, early, cutoff_us=0.92))
    assert features["t_slope2"] <= t_window[-1] and features["t_slope1"] <= features["t_slope2"]
    assert features["v_slope1"] == features["v_slope2"] == 213.0
