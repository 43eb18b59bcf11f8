"""How much the copper example's two shots can tell about A: the profile likelihood from the hydrocode itself.

No emulator and no sampler: the hydrocode (`run_shot`) and the study's extractor on its noise-free traces, at the
truth of examples/copper/make_records.py and around it, against the study's own observation sds (1% of each
measured feature and the extractor's read-out sd on the 0.5% white-noise records, in quadrature, as `shockcal
observed` and `shockcal.inference.problem` compute them). Printed, not asserted:

  1. the records' observed features and the sd of each of the 8 calibration features;
  2. the Fisher matrix at the truth (central differences, 1% of each box) and each input's implied 90% width
     over its box (2 x 1.645 sd / box, all other inputs free);
  3. the profile chi-square of A on a grid across its box: (a) the other inputs at their linearised conditional
     optimum (Fisher), clipped to the box, one hydrocode pair each; (b) C and n refitted by least squares from
     there (the other inputs kept at (a)'s values). Both are upper bounds of the full profile's chi-square, so
     the A range where they stay below 2.71 (chi-square, 1 dof, 90%) is a lower bound of the information-limited
     width of A's 90% interval.

    .venv/bin/python benchmarks/copper_identifiability.py [--config examples/copper/config.yaml] [--grid 9]

The config's records must exist (`python examples/copper/make_records.py --out studies/copper/records`).
About 5 CPU-min (the read-out bootstrap 200 replicates a shot, about 120 hydrocode runs of 0.6 s).
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from scipy.optimize import least_squares

from shockcal.hydro import run_shot
from shockcal.inference.problem import observed_vector, readout_vector
from shockcal.study.adapters import extractor_settings, hydro_inputs, observed_table, shot_mapping
from shockcal.study.config import prior_bounds, shot_config
from shockcal.study.validate import load_config
from shockcal.velocimetry.columns import CALIBRATION_FEATURES
from shockcal.velocimetry.features import extract_features

TRUTH = dict(A=9.0e-4, B=2.92e-3, C=0.025, n=0.31, m=1.09, V1=0.030, V2=0.050, G=0.46)  # make_records.py's, config units
CHI2_90 = 2.706   # chi-square with 1 dof, 90%
FISHER_STEP = 0.01  # central-difference step, share of each box


class Features:
    """The 8 calibration features (m/s, shot-major) of the hydrocode at a design row, cached by row."""

    def __init__(self, config: dict):
        self.config, self.shots, self.cache, self.runs = config, list(config["shots"]), {}, 0
        self.inputs = {shot: shot_mapping(config, shot).inputs() for shot in self.shots}

    def shot(self, shot: str, row: dict) -> np.ndarray:
        key = (shot, *(round(row[k], 12) for k in self.inputs[shot]))
        if key not in self.cache:
            spec = shot_config(self.config, shot)
            run = run_shot(shot_mapping(self.config, shot).parameters(row), *hydro_inputs(self.config, spec))
            if run.status != "ok":
                raise RuntimeError(f"{shot} at {row}: {run.reason}")
            features = extract_features(run.t_us, run.v_m_s, extractor_settings(self.config, shot))
            self.cache[key] = np.array([features[f] for f in CALIBRATION_FEATURES])
            self.runs += 1
        return self.cache[key]

    def __call__(self, row: dict) -> np.ndarray:
        return np.concatenate([self.shot(shot, row) for shot in self.shots])


def fisher_jacobian(model: Features, names, box) -> np.ndarray:
    """d features / d input (m/s per box width), central differences of FISHER_STEP of each box."""
    columns = []
    for name in names:
        width = box[name][1] - box[name][0]
        up, down = dict(TRUTH), dict(TRUTH)
        up[name] += FISHER_STEP * width
        down[name] -= FISHER_STEP * width
        columns.append((model(up) - model(down)) / (2 * FISHER_STEP))
    return np.column_stack(columns)


def crossings(steps: np.ndarray, chi: np.ndarray) -> tuple[float, float]:
    """Where chi2(A) crosses CHI2_90 on each side of its smallest grid value (A - truth, box units), linear in
    sqrt(chi2) between grid points (exact for a quadratic chi2); a side that stays below ends at the box."""
    root, level, best = np.sqrt(chi), np.sqrt(CHI2_90), int(np.argmin(chi))
    ends = []
    for side in (range(best, 0, -1), range(best, len(steps) - 1)):
        end = steps[0] if side.step < 0 else steps[-1]
        for i in side:
            j = i - 1 if side.step < 0 else i + 1
            if root[j] >= level:
                end = steps[i] + (steps[j] - steps[i]) * (level - root[i]) / (root[j] - root[i])
                break
        ends.append(float(end))
    return ends[0], ends[1]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--config", default="examples/copper/config.yaml")
    parser.add_argument("--grid", type=int, default=9, help="A values across its box")
    args = parser.parse_args(argv)
    start = time.process_time()
    config = load_config(args.config)
    shots, box = list(config["shots"]), prior_bounds(config)
    names = list(config["inputs"])
    labels = [f"{shot}:{f}" for shot in shots for f in CALIBRATION_FEATURES]

    table = observed_table(config)
    y_obs = observed_vector(table, shots, CALIBRATION_FEATURES, "observed")
    readout = readout_vector(table, shots, CALIBRATION_FEATURES, "observed")
    sd = np.hypot(config["observed"]["sd_fraction"] * np.abs(y_obs), readout)
    model = Features(config)
    y_true = model(TRUTH)
    print(f"1. features (m/s): noise-free truth, the records' read, read-out sd, observation sd "
          f"(1% and read-out in quadrature)   [{time.process_time() - start:.0f} CPU-s]")
    for label, a, b, r, s in zip(labels, y_true, y_obs, readout, sd, strict=True):
        print(f"   {label:14s} {a:8.2f} {b:8.2f} {r:6.2f} {s:6.2f}   (record - truth) / sd = {(b - a) / s:+.2f}")

    jac = fisher_jacobian(model, names, box)
    whitened = jac / sd[:, None]
    fisher = whitened.T @ whitened
    cov = np.linalg.inv(fisher)
    print(f"\n2. Fisher at the truth (central differences, {FISHER_STEP:g} of each box; {model.runs} runs so far)")
    print("   input   90% width / box, all others free   A fixed too?   d features / d input (m/s per box), largest")
    for i, name in enumerate(names):
        top = np.argsort(-np.abs(whitened[:, i]))[:2]
        print(f"   {name:4s}    {2 * 1.645 * np.sqrt(cov[i, i]):7.3f}          only this input free: "
              f"{2 * 1.645 / np.sqrt(fisher[i, i]):6.3f}   "
              + ", ".join(f"{labels[j]} {jac[j, i]:+.1f}" for j in top))
    a = names.index("A")
    others = [i for i in range(len(names)) if i != a]
    for fixed in (["C"], ["n"], ["C", "n"]):
        keep = [i for i in range(len(names)) if names[i] not in fixed]
        sub = np.linalg.inv(fisher[np.ix_(keep, keep)])
        print(f"   A's 90% width / box with {' and '.join(fixed)} known: {2 * 1.645 * np.sqrt(sub[keep.index(a), keep.index(a)]):.3f}")
    slope = -np.linalg.solve(fisher[np.ix_(others, others)], fisher[others, a])   # d other / d A, in box units

    width = {k: box[k][1] - box[k][0] for k in names}
    print(f"\n3. Profile chi-square of A against the noise-free truth features; threshold {CHI2_90} (90%, 1 dof)")
    print("   A (Mbar)  (A - truth)/box  chi2 linear-optimum others   chi2 C, n refitted   C, n refitted")
    rows = []
    for value in np.linspace(box["A"][0], box["A"][1], args.grid):
        step = (value - TRUTH["A"]) / width["A"]
        row = dict(TRUTH, A=value)
        for j, i in enumerate(others):
            name = names[i]
            row[name] = float(np.clip(TRUTH[name] + slope[j] * step * width[name], *box[name]))
        chi_linear = float(np.sum(((model(row) - y_true) / sd) ** 2))
        free = ["C", "n"]
        unit = np.array([(row[k] - box[k][0]) / width[k] for k in free])

        def residual(u, row=row, free=free):
            trial = dict(row, **{k: box[k][0] + x * width[k] for k, x in zip(free, u, strict=True)})
            return (model(trial) - y_true) / sd

        fit = least_squares(residual, unit, bounds=(0.0, 1.0), diff_step=0.02, max_nfev=5, x_scale=0.1)
        refit = {k: box[k][0] + x * width[k] for k, x in zip(free, fit.x, strict=True)}
        chi_refit = min(chi_linear, 2 * fit.cost)
        rows.append((step, chi_linear, chi_refit))
        print(f"   {value:.2e}  {step:+6.3f}          {chi_linear:8.2f}              {chi_refit:8.2f}        "
              f"C {refit['C']:.4f}, n {refit['n']:.3f}   [{model.runs} runs, {time.process_time() - start:.0f} CPU-s]")
    steps, chi_lin, chi_fit = (np.array(c) for c in zip(*rows, strict=True))
    for label, chi in (("linear-optimum others", chi_lin), ("C, n refitted", chi_fit)):
        low, high = crossings(steps, chi)
        print(f"   chi2 < {CHI2_90} ({label}): A - truth from {low:+.3f} to {high:+.3f} of the box (crossings "
              f"interpolated linearly in sqrt(chi2) between grid points): width {high - low:.3f} of the box")
    print(f"   Fisher (Gaussian) width: {2 * 1.645 * np.sqrt(cov[a, a]):.3f} of the box; the goal: 0.30; the study's "
          f"posterior: 0.52   [{model.runs} hydrocode runs, {time.process_time() - start:.0f} CPU-s]")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
