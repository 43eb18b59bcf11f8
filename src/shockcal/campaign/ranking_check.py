"""The realized check of the next-shot ranking (docs/next_shot.md): truths drawn from the joint
posterior, and what their calibrations with and without a candidate shot realized against what the
ranking predicted.

A truth is a row of the joint posterior's equal-weight draws (`candidates.candidate_design`: its
inputs, its `lambda_y`, and per candidate the velocity and shear modulus the ranking's model draws),
with the candidate's two inputs as a fourth shot reads them: its impact velocity (cm/us) and, for a hot
candidate, its shear-modulus increment over the reference shot's, G_ref s (T0 - T_ref) (Mbar).

The realized gain about the targets is the yardstick of the ranking's `eig_nats` (the Gaussian entropy
bound on rank normal scores, `next_shot`): each target is mapped to normal scores by the current joint
posterior's marginal (z = Phi^-1(F(x)), F its empirical CDF), and

    gain = 0.5 log det Cov(z | three shots) - 0.5 log det Cov(z | three shots and the candidate),

both covariances over the equal-weight draws of the truth's two calibrations (the Gaussian entropy
difference: exact for Gaussian scores, the same approximation the prediction makes).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
import pandas as pd

from shockcal.campaign.candidates import SHEAR_MODULUS, VELOCITY, Candidate, candidate_design
from shockcal.campaign.next_shot import normal_scores
from shockcal.errors import InputError
from shockcal.hydro import MaterialProperties
from shockcal.inference.problem import LAMBDA_Y


def truth_design(posterior: pd.DataFrame, names: Sequence[str], candidates: Mapping[str, tuple[Candidate, str, str | None]],
                 n: int, seed: int, material: MaterialProperties, velocity_sd_fraction: float,
                 slope_per_K: tuple[float, float], bounds: Mapping[str, tuple[float, float]] | None = None,
                 source: str = "posterior") -> tuple[pd.DataFrame, dict[str, pd.DataFrame]]:
    """`n` joint-posterior draws as truths for every candidate at once.

    Args:
        posterior: the joint posterior's equal-weight draws (inputs in Table IV units, `lambda_y`).
        names: the study's inputs.
        candidates: name -> (the candidate, its velocity input's name, its shear-modulus increment's name
            or None for a candidate at the reference temperature, whose modulus is the reference shot's).
        n: truths.
        seed: the draws' seed (`candidate_design`: the same rows and nuisance inputs for every candidate).
        material: the material (its T_ref_K).
        velocity_sd_fraction: the new shot's impact-velocity error, a fraction (sd).
        slope_per_K: (min, max) of d ln G / dT (1/K) of a hot candidate.
        bounds: the prior box by input; every draw must lie in it.
        source: names `posterior` in errors.

    Returns (truths, designs): the truths' `run`, the inputs, `lambda_y` and per candidate its velocity
    input (cm/us) and increment (Mbar); and per candidate its `candidate_design` of the same rows (the
    columns its runs read).
    """
    if not candidates:
        raise InputError("next-shot check: no candidates to draw truths for")
    designs = {name: candidate_design(posterior, names, candidate, n, seed, material, velocity_sd_fraction,
                                      slope_per_K, bounds, source)
               for name, (candidate, _, _) in candidates.items()}
    truths = next(iter(designs.values()))[["run", *names, LAMBDA_Y]].copy()
    for name, (candidate, velocity_input, increment_input) in candidates.items():
        design = designs[name]
        truths[velocity_input] = design[VELOCITY]
        if increment_input is not None:
            truths[increment_input] = design[SHEAR_MODULUS] - design[list(candidate.shear_modulus_inputs)].sum(axis=1)
    return truths, designs


def realized_gain(reference: np.ndarray, before: np.ndarray, after: np.ndarray) -> float:
    """The Gaussian entropy difference (nats) of the targets from the draws `before` (M1, d) to the draws
    `after` (M2, d), both on the normal scores of `reference`'s marginals (`normal_scores`; module docstring)."""
    def half_logdet(draws):
        cov = np.atleast_2d(np.cov(normal_scores(reference, draws), rowvar=False))
        sign, logdet = np.linalg.slogdet(cov)
        if sign <= 0:
            raise InputError("realized gain: the draws' normal scores have a singular covariance (a target "
                             "that does not vary)")
        return 0.5 * logdet

    return half_logdet(before) - half_logdet(after)


def check_table(reference: pd.DataFrame, baseline: pd.DataFrame, with_candidate: Mapping[str, pd.DataFrame],
                targets: Sequence[str]) -> pd.DataFrame:
    """Per truth and candidate, what its calibrations realized.

    Args:
        reference: the current joint posterior's equal-weight draws (the normal scores' marginals).
        baseline: the three-shot calibrations' equal-weight draws of every truth (`run`: the truth, the targets).
        with_candidate: candidate -> the same with the candidate shot added.
        targets: the parameters of interest.

    Returns `run, candidate, gain_nats`, and per target `baseline_sd_<p>` and `sd_<p>` (its unit), for the
    truths both calibrations finished.
    """
    targets = list(targets)
    ref = reference[targets].to_numpy(float)
    rows = []
    for name, table in with_candidate.items():
        for run in sorted(set(baseline["run"]) & set(table["run"])):
            before = baseline.loc[baseline["run"] == run, targets].to_numpy(float)
            after = table.loc[table["run"] == run, targets].to_numpy(float)
            row = {"run": int(run), "candidate": name, "gain_nats": realized_gain(ref, before, after)}
            for j, target in enumerate(targets):
                row[f"baseline_sd_{target}"] = float(before[:, j].std(ddof=1))
                row[f"sd_{target}"] = float(after[:, j].std(ddof=1))
            rows.append(row)
    return pd.DataFrame(rows)


def _mean_se(values) -> tuple[float, float]:
    values = np.asarray(values, float)
    return float(values.mean()), float(values.std(ddof=1) / np.sqrt(len(values)))


def check_summary(check: pd.DataFrame, ranking: pd.DataFrame, best: str, worst: str, targets: Sequence[str],
                  source: str = "ranking") -> pd.DataFrame:
    """The realized check against the prediction.

    Args:
        check: `check_table`'s rows.
        ranking: the ranking (`candidate`, `eig_nats`, `prior_sd_<p>`, `expected_sd_<p>`).
        best, worst: the candidates compared (the best- and the worst-ranked by default).
        targets: the parameters of interest.
        source: names `ranking` in errors.

    Returns rows `row, quantity, predicted, realized_mean, realized_se, n_truths, verdict`: per candidate
    (row = its name) the gain about the targets (`gain_nats`: predicted eig_nats) and each target's sd before
    (`baseline_sd_<p>`: predicted the ranking's prior_sd_<p>) and after the shot (`sd_<p>`: expected_sd_<p>),
    mean and standard error over the truths; then (row `<best> - <worst>`) the paired differences over the
    truths both have, of the gain and of each target's ln sd, with the verdict "holds" when the realized
    difference has the predicted sign and lies more than 2 standard errors from 0, else "does not hold".
    """
    targets = list(targets)
    ranked = ranking.set_index("candidate")
    missing = [c for c in (best, worst) if c not in ranked.index]
    if missing:
        raise InputError(f"{source}: no row of candidate(s) {missing}")
    if check["run"].nunique() < 2:
        raise InputError("next-shot check: fewer than 2 truths finished; a standard error needs 2")
    rows = []
    for name in dict.fromkeys([best, worst]):
        mine, pred = check[check["candidate"] == name], ranked.loc[name]
        quantities = [("gain_nats", pred["eig_nats"]),
                      *((f"baseline_sd_{p}", pred[f"prior_sd_{p}"]) for p in targets),
                      *((f"sd_{p}", pred[f"expected_sd_{p}"]) for p in targets)]
        for quantity, predicted in quantities:
            mean, se = _mean_se(mine[quantity])
            rows.append({"row": name, "quantity": quantity, "predicted": float(predicted), "realized_mean": mean,
                         "realized_se": se, "n_truths": len(mine), "verdict": ""})
    paired = check[check["candidate"] == best].merge(check[check["candidate"] == worst], on="run",
                                                     suffixes=("_best", "_worst"))
    differences = [("gain_nats", ranked.loc[best, "eig_nats"] - ranked.loc[worst, "eig_nats"],
                    paired["gain_nats_best"] - paired["gain_nats_worst"])]
    differences += [(f"ln_sd_{p}", np.log(ranked.loc[best, f"expected_sd_{p}"] / ranked.loc[worst, f"expected_sd_{p}"]),
                     np.log(paired[f"sd_{p}_best"] / paired[f"sd_{p}_worst"])) for p in targets]
    for quantity, predicted, realized in differences:
        mean, se = _mean_se(realized) if len(realized) >= 2 else (float("nan"), float("nan"))
        rows.append({"row": f"{best} - {worst}", "quantity": quantity, "predicted": float(predicted),
                     "realized_mean": mean, "realized_se": se, "n_truths": len(realized),
                     "verdict": verdict(float(predicted), mean, se)})
    return pd.DataFrame(rows)


def verdict(predicted: float, realized_mean: float, realized_se: float) -> str:
    """"holds" when the realized difference has the predicted sign and is more than 2 standard errors from 0."""
    beyond = np.isfinite(realized_mean) and abs(realized_mean) > 2 * realized_se
    return "holds" if beyond and np.sign(realized_mean) == np.sign(predicted) != 0 else "does not hold"
