"""`shockcal verify`: the hydrocode's verdict on the joint posterior (shockcal.inference.verify).

Reads the verify run set's design (`shockcal predict --stream verify`: S joint-posterior draws with their
lambda_y), the hydrocode's features at those draws per shot, the emulator and the observed features; writes
`--out` (CSV: per calibrated input, user units, the emulator's and the corrected 5/50/95% points, k-hat and
its threshold, the emulator's error at the draws against the records' sd) and `--error-out` (CSV: that error per
shot and feature), and logs the verdict and the error in a line each.
"""

from __future__ import annotations

from shockcal.cli import add_command, add_config_argument

EXAMPLE_VERIFY = """\
shockcal verify --config config/config.yaml --design results/verify/design.parquet \\
    --features 104S=results/verify/features/104S.parquet 105S=results/verify/features/105S.parquet \\
    --emulator results/emulator --observed results/features/observed.parquet --out results/verify/summary.csv \\
    --error-out results/verify/emulator_error.csv"""


def register(subparsers) -> None:
    p = add_command(subparsers, "verify", example=EXAMPLE_VERIFY,
                    help="the hydrocode's verdict on the joint posterior: PSIS k-hat and corrected quantiles")
    add_config_argument(p)
    p.add_argument("--design", required=True, help="the draws run (`shockcal predict --stream verify`)")
    p.add_argument("--features", required=True, nargs="+", metavar="SHOT=TABLE",
                   help="the hydrocode's features at the draws, one table per shot")
    p.add_argument("--emulator", required=True, help="emulator directory written by `shockcal emulate`")
    p.add_argument("--observed", required=True, help="observed features table")
    p.add_argument("--out", required=True, help="output CSV summary")
    p.add_argument("--error-out", required=True, help="output CSV: the emulator's error at the draws, per feature")
    p.set_defaults(func=run)


def read_shot_features(paths: dict, shots: list[str], feature_names: list[str]) -> dict:
    """shot -> the hydrocode's features table at the draws (`run`, `status`, the features, m/s), in `shots`' order;
    a table without `status` is all "ok". A shot without a table or a missing column is an InputError."""
    from shockcal.errors import InputError
    from shockcal.io import read_table

    tables = {}
    for shot in shots:
        if shot not in paths:
            raise InputError(f"--features: no table for shot {shot} (have {sorted(paths)})")
        table = read_table(paths[shot])
        missing = [c for c in ["run", *feature_names] if c not in table.columns]
        if missing:
            raise InputError(f"{paths[shot]}: columns {missing} missing")
        tables[shot] = table if "status" in table.columns else table.assign(status="ok")
    return tables


def hydrocode_features(tables: dict, feature_names: list[str], runs) -> tuple:
    """The (S, shots x features) hydrocode features at design `runs`, shot-major in `tables`' order, and a mask of
    the draws every shot's run gave features for (a failed run: status not ok, or a missing row)."""
    import numpy as np

    blocks = [table[table["status"].eq("ok")].set_index("run").reindex(runs)[feature_names].to_numpy(float)
              for table in tables.values()]
    features = np.concatenate(blocks, axis=1)
    return features, np.isfinite(features).all(axis=1)


def run(args) -> int:
    import logging

    import numpy as np

    from shockcal.cli import parse_pairs
    from shockcal.cli.calibrate import study_emulator
    from shockcal.errors import InputError
    from shockcal.inference.problem import LAMBDA_Y, Problem
    from shockcal.inference.settings import VerifySettings
    from shockcal.inference.verify import corrected_quantiles, emulator_error_at_draws, psis_verdict
    from shockcal.io import read_table, require_columns
    from shockcal.study.adapters import load_study_design
    from shockcal.study.config import input_columns, input_user_units, prior_bounds
    from shockcal.study.stages import load_stage_config

    log = logging.getLogger("shockcal.verify")
    config = load_stage_config(args.config, "verify")
    settings = VerifySettings(**config["verify"], discrepancy=config["calibration"]["discrepancy"])
    emulator = study_emulator(args.emulator, config)
    shots = list(config["shots"])
    units = {name: box["unit"] for name, box in config["inputs"].items()}
    problem = Problem.for_shots(emulator, shots, read_table(args.observed), config["observed"]["sd_fraction"],
                                args.observed, prior_bounds(config), units)
    design = load_study_design(args.design, config, problem.names)   # checked against the box; lambda_y beside it
    lambda_y = read_table(args.design)
    require_columns(lambda_y, ["run", LAMBDA_Y], args.design)
    design[LAMBDA_Y] = lambda_y.set_index("run")[LAMBDA_Y].reindex(design["run"]).to_numpy(float)
    if len(design) != settings.n_draws:
        raise InputError(f"{args.design}: {len(design)} draws, verify.n_draws is {settings.n_draws}; "
                         "redraw them (`shockcal predict --stream verify`)")
    tables = read_shot_features(parse_pairs(args.features, "--features"), shots, emulator.feature_names)
    features, ok = hydrocode_features(tables, emulator.feature_names, design["run"].to_numpy())
    if not ok.all():
        log.warning("%d of %d draws have a failed hydrocode run at some shot; verifying on the other %d",
                    int((~ok).sum()), len(ok), int(ok.sum()))
    if not ok.any():
        raise InputError(f"{args.design}: no draw has features at every shot")
    points = design.loc[ok, [*problem.names, LAMBDA_Y]].to_numpy(float)
    verdict = psis_verdict(problem.hydrocode_log_likelihood(features[ok], points[:, -1]),
                           problem.log_likelihood(points))
    columns = input_columns(config)
    user = points[:, :-1] * np.array([columns[name][2] for name in problem.names])
    table = corrected_quantiles(user, [columns[name][0] for name in problem.names], verdict)
    table.insert(1, "unit", [input_user_units(config)[name] for name in problem.names])
    error = emulator_error_at_draws(emulator, design[["run", *problem.names]], tables, problem.obs_sd)
    table["emulator_rmse_m_s"], table["emulator_rmse_records_sd"] = error.rmse_m_s, error.rmse_records_sd
    table["emulator_region_coverage"] = error.region
    table.to_csv(args.out, index=False)
    error.table.to_csv(args.error_out, index=False)
    log.info("%s\n%s\n%s\n%s", verdict.line(), error.line(), table.to_string(index=False, float_format="%.4g"),
             error.table.to_string(index=False, float_format="%.3g"))
    return 0
