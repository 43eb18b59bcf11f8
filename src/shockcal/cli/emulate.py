"""`shockcal emulate`: fit the PC-GP emulator to design + features and write its LOO cross-validation."""

from __future__ import annotations

from shockcal.cli import add_config_argument, parse_pairs


def register(subparsers) -> None:
    p = subparsers.add_parser("emulate", help="fit the emulator; write it and its leave-one-out table")
    add_config_argument(p)
    p.add_argument("--design", required=True, help="design table (CSV or Parquet, Table IV units)")
    p.add_argument("--features", required=True, nargs="+", metavar="SHOT=FILE",
                   help="per-shot feature tables (CSV or Parquet), joined to the design on `run`")
    p.add_argument("--structure", choices=["per_shot", "joint"], help="override emulator.structure")
    p.add_argument("--out", required=True, help="output directory (emulator.json, emulator.npz, cv.parquet, cv_rmse.csv)")
    p.set_defaults(func=run)

    cv = subparsers.add_parser("emulate-cv", help="print the leave-one-out RMSE table of a fitted emulator")
    cv.add_argument("--emulator", required=True, help="emulator directory")
    cv.set_defaults(func=print_cv)


def run(args) -> int:
    import logging
    from pathlib import Path

    from shockcal.config import load_config, shot_config
    from shockcal.design import load_design
    from shockcal.emulator import fit_emulator, rmse_table
    from shockcal.io import read_table, write_table

    config = load_config(args.config)
    if args.structure:
        config["emulator"]["structure"] = args.structure
    paths = parse_pairs(args.features, "--features")
    for shot in paths:
        shot_config(config, shot)
    design = load_design(args.design, config)
    features = {shot: read_table(path) for shot, path in paths.items()}
    emulator = fit_emulator(config, design, features, sources=paths)
    out = Path(args.out)
    emulator.save(out)
    cv = emulator.cv_table()
    write_table(cv, out / "cv.parquet", {"table": "emulator leave-one-out", "structure": emulator.structure,
                                         "units": {"simulated": "m/s", "predicted": "m/s", "predicted_sd": "m/s"}})
    table = rmse_table(cv)
    table.to_csv(out / "cv_rmse.csv", index=False)
    logging.getLogger("shockcal.emulate").info("leave-one-out RMSE (m/s):\n%s", table.to_string(index=False))
    return 0


def print_cv(args) -> int:
    from pathlib import Path

    from shockcal.emulator import rmse_table
    from shockcal.io import read_table

    print(rmse_table(read_table(Path(args.emulator) / "cv.parquet")).to_string(index=False))
    return 0
