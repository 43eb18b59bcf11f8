"""The study emulator's errors on the hydrocode-truth runs, which it never saw, measured against its own
predictive covariance (docs/calibration.md, "Measured: hydrocode truth").

Per feature: RMSE (m/s), the emulator's median sd, the share of errors inside its 90% band and the mean
z^2 (1 when the sds are right). Then the 12-feature Mahalanobis distance of each run's error against
chi-square: its mean, the share beyond the 90% point (0.10 when the covariance is right), the same with
the calibration's observation noise added and for errors drawn from the emulator itself, and the
runs with the largest distances. The shots and the noise's sd fraction come from the study's config;
the noise is drawn as the check draws it. Needs `make check`'s check runs and the emulator under the
results directory; prints, never asserts.
Usage: python benchmarks/emulator_tails.py [RESULTS_DIR [CONFIG]]
"""

import sys
from pathlib import Path

import numpy as np
import pandas as pd
from scipy import stats

from shockcal.calibration import HydroTruths, _noisy_features
from shockcal.config import load_config
from shockcal.emulator import Emulator

NOISE_DRAWS = 50


def mahalanobis(err: np.ndarray, cov: np.ndarray) -> np.ndarray:
    return np.einsum("ni,nij,nj->n", err, np.linalg.inv(cov), err)


def share_beyond_90(eta, cov, errors, sd_fraction, rng) -> float:
    """Share of (run, noise draw) residuals beyond chi-square's 90% point under emulator + noise
    covariance; the noise drawn by the check's own `_noisy_features` (lambda_y from its prior)."""
    limit, beyond = stats.chi2.ppf(0.9, eta.shape[1]), []
    for _ in range(NOISE_DRAWS):
        lam, noisy = zip(*(_noisy_features(e, sd_fraction, rng, run) for run, e in enumerate(eta)))
        noise_sd = sd_fraction * np.abs(eta) / np.sqrt(np.array(lam))[:, None]
        total = errors() + (np.array(noisy) - eta)
        beyond.append(mahalanobis(total, cov + np.einsum("ni,ij->nij", noise_sd**2, np.eye(eta.shape[1]))) > limit)
    return float(np.mean(beyond))


def main(results: Path, config_path: Path) -> int:
    if not (results / "check" / "design.parquet").exists():
        print(f"skipped: no check runs under {results} (run `make check` first)")
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
    d2, dof = mahalanobis(err, cov), eta.shape[1]
    print(f"Mahalanobis distance: mean {d2.mean():.2f} (chi-square({dof}): {dof}), share beyond its 90% point "
          f"{(d2 > stats.chi2.ppf(0.9, dof)).mean():.2f} (0.10), KS p {stats.kstest(d2, stats.chi2(dof).cdf).pvalue:.3g}")
    rng = np.random.default_rng(1)
    chol = np.linalg.cholesky(cov)
    print(f"with observation noise: share beyond {share_beyond_90(eta, cov, lambda: err, sd_fraction, rng):.3f}; "
          "errors drawn from the emulator's own covariance: "
          f"{share_beyond_90(eta, cov, lambda: np.einsum('nij,nj->ni', chol, rng.normal(size=eta.shape)), sd_fraction, rng):.3f}")
    top = np.argsort(d2)[::-1][:5]
    print("largest distances (run order among the usable runs: distance, worst feature, its |z|):")
    for i in top:
        j = np.abs(z[i]).argmax()
        print(f"  {i}: {d2[i]:.1f}, {columns[j]}, {abs(z[i, j]):.1f}")
    return 0


if __name__ == "__main__":
    args = sys.argv[1:]
    sys.exit(main(Path(args[0] if args else "results"), Path(args[1] if len(args) > 1 else "config/config.yaml")))
