"""The study emulator's errors on the hydrocode-truth runs, which it never saw, measured against its own
predictive distribution (docs/emulator.md, "Error tails"; docs/calibration.md, "Hydrocode truth").

Per feature: RMSE (m/s), the emulator's median sd, the share of errors inside its 90% band and the mean
z^2 (1 when the sds are right). Then, per emulator block, the Mahalanobis distance of each run's error
under the covariance, against the Gaussian (chi-square) and against the block's fitted error model (a
Student t: d^2 / (F scale) ~ F(F, dof)): the share beyond each one's 90% and 99% points (0.10 and 0.01
when the model is right) and the KS p-value; with the calibration's observation noise added, the share
of real residuals beyond the 90% point of residuals the model draws itself; and the runs with the
largest distances. Last, where in the box the errors outgrow the emulator's sd: per fifth of each input's
box, the mean d^2 / F of the check runs and the mean z^2 of the K-fold errors of the training runs
(results/emulator/cv_heldout.parquet), both 1 when the sds are right. The shots and the noise's sd
fraction come from the study's config; the noise is drawn as the check draws it. Needs `make check`'s
check runs and the emulator under the results directory; prints, never asserts.
Usage: python benchmarks/emulator_tails.py [RESULTS_DIR [CONFIG]] (default results and config/config.yaml, the paper's
study after `make paper` and `make check STUDY=paper`; the default study: results/sequential and its
results/sequential/config/effective.yaml)
"""

import sys
from pathlib import Path

import numpy as np
import pandas as pd
from scipy import stats

from shockcal.emulator.error_model import ErrorModel
from shockcal.emulator.study_emulator import Emulator
from shockcal.inference.coverage import HydroTruths, _noisy_features
from shockcal.study.validate import load_config

NOISE_DRAWS = 50


def mahalanobis(err: np.ndarray, cov: np.ndarray) -> np.ndarray:
    return np.einsum("ni,nij,nj->n", err, np.linalg.inv(cov), err)


def distance_cdf(model: ErrorModel, dof_features: int):
    """CDF of d^2 under the model's own covariance scale: chi-square, or F-distributed for a t."""
    if np.isinf(model.dof):
        return stats.chi2(dof_features, scale=model.scale).cdf
    return stats.f(dof_features, model.dof, scale=dof_features * model.scale).cdf


def share_beyond_90_with_noise(eta, cov, err, model: ErrorModel, sd_fraction, rng) -> float:
    """Share of real residuals (error + noise) whose distance under cov + noise covariance lies beyond
    the 90% point of the same distance for residuals the model draws itself (its error + the same
    noise): 0.10 when the model describes error + noise. The noise is drawn by the check's own
    `_noisy_features` (lambda_y from its prior)."""
    f, real, simulated = eta.shape[1], [], []
    for _ in range(NOISE_DRAWS):
        lam, noisy = zip(*(_noisy_features(e, sd_fraction, rng, run) for run, e in enumerate(eta)))
        noise = np.array(noisy) - eta
        shape = cov + np.einsum("ni,ij->nij", (sd_fraction * np.abs(eta)) ** 2 / np.array(lam)[:, None], np.eye(f))
        drawn = np.array([model.sample(np.zeros(f), c, rng) for c in cov])
        real.append(mahalanobis(err + noise, shape))
        simulated.append(mahalanobis(drawn + noise, shape))
    return float(np.mean(np.concatenate(real) > np.quantile(np.concatenate(simulated), 0.9)))


def main(results: Path, config_path: Path) -> int:
    if not (results / "check" / "design.parquet").exists():
        print(f"skipped: no check runs under {results} (run `make check STUDY=paper` first)")
        return 0
    config = load_config(config_path)
    shots, sd_fraction = list(config["shots"]), config["observed"]["sd_fraction"]
    emulator = Emulator.load(results / "emulator")
    truths = HydroTruths.read(results / "check" / "design.parquet",
                              {s: results / "check" / "features" / f"{s}.parquet" for s in shots}, shots)
    names = emulator.required_inputs(shots)
    pairs = truths.table(names, shots)
    theta, eta = np.array([p[0] for p in pairs]), np.array([p[1] for p in pairs])
    mean, cov = emulator.predict(dict(zip(names, theta.T)), shots)
    err = eta - mean
    sd = np.sqrt(np.einsum("nii->ni", cov))
    z = err / sd
    columns = [f"{s}:{f}" for s in shots for f in emulator.feature_names]
    print(f"{len(eta)} check runs")
    print(pd.DataFrame({"rmse_m_s": np.sqrt((err**2).mean(0)), "emulator_sd_median_m_s": np.median(sd, 0),
                        "inside_90_band": (np.abs(z) <= stats.norm.ppf(0.95)).mean(0), "mean_z2": (z**2).mean(0)},
                       index=columns).round(3).to_string())
    rng = np.random.default_rng(1)
    for cols, fitted in emulator.error_groups(shots):
        e, c, f = err[:, cols], cov[:, cols[:, None], cols[None, :]], len(cols)
        d2 = mahalanobis(e, c)
        print(f"\nblock {'+'.join(columns[i] for i in cols[[0, -1]])} ({f} features): Mahalanobis mean {d2.mean():.2f}")
        for label, model in [("gaussian", ErrorModel()), (f"student t (dof {fitted.dof:.2f}, scale {fitted.scale:.3f})",
                                                          fitted)]:
            u = distance_cdf(model, f)(d2)
            print(f"  {label}: beyond 90% point {(u > 0.9).mean():.2f} (0.10), beyond 99% {(u > 0.99).mean():.2f} "
                  f"(0.01), KS p {stats.kstest(u, 'uniform').pvalue:.3g}")
            print(f"    with observation noise: beyond the 90% point of the model's own residuals "
                  f"{share_beyond_90_with_noise(eta[:, cols], c, e, model, sd_fraction, rng):.3f} (0.10)")
        top = np.argsort(d2)[::-1][:5]
        print("  largest distances (run order among the usable runs: distance, worst feature, its |z|):")
        for i in top:
            j = cols[np.abs(z[i, cols]).argmax()]
            print(f"    {i}: {d2[i]:.1f}, {columns[j]}, {abs(z[i, j]):.1f}")
    print_by_input_fifth(results, emulator, names, theta, mahalanobis(err, cov) / err.shape[1])
    return 0


def print_by_input_fifth(results: Path, emulator: Emulator, names, theta, d2_per_feature) -> None:
    """Mean d^2 / F of the check runs and mean K-fold z^2 of the training runs, per fifth of each input's box."""
    lower, upper = emulator.input_bounds(names)

    def fifths(x):
        return np.clip(((x - lower) / (upper - lower) * 5).astype(int), 0, 4)

    cv = pd.read_parquet(results / "emulator" / "cv_heldout.parquet").query("scheme == 'kfold'")
    z2 = ((cv["predicted"] - cv["simulated"]) / cv["predicted_sd"]) ** 2
    kfold = cv.assign(z2=z2).groupby("run")["z2"].mean()
    design = pd.read_parquet(results / "training" / "design.parquet").set_index("run").loc[kfold.index, names]
    check_bin, kfold_bin = fifths(theta), fifths(design.to_numpy())
    print("\nmean d^2 / F of the check runs | mean K-fold z^2 of the training runs, per fifth of each input's box "
          "(1 when the sds are right):")
    rows = {name: [f"{d2_per_feature[check_bin[:, j] == k].mean():.2f} | {kfold.to_numpy()[kfold_bin[:, j] == k].mean():.2f}"
                   for k in range(5)] for j, name in enumerate(names)}
    print(pd.DataFrame(rows, index=[f"fifth {k + 1}" for k in range(5)]).T.to_string())


if __name__ == "__main__":
    args = sys.argv[1:]
    sys.exit(main(Path(args[0] if args else "results"), Path(args[1] if len(args) > 1 else "config/config.yaml")))
