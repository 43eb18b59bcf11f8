"""`shockcal emulate` and `emulate-cv`: fit the PC-GP emulator and cross-validate it; its cross-validation
table. (Its predictions at a design's rows: `shockcal predict-emulator`.)

emulate reads the design and each shot's features table and writes the emulator directory
(emulator.json, emulator.npz) with its cross-validation tables; config keys: `emulator`, `inputs`,
`checks.design_box`, the shots' mappings, study.seed (shockcal.study.stages declares them)."""

from __future__ import annotations

from shockcal.cli import add_command, add_config_argument, parse_pairs

HELD_OUT = ("kfold", "outer")
UNITS = {"simulated": "m/s", "predicted": "m/s", "predicted_sd": "m/s"}

EXAMPLE_EMULATE = """\
shockcal emulate --config config/config.yaml --design results/training/design.parquet \\
    --features 104S=results/training/features/104S.parquet 105S=results/training/features/105S.parquet \\
    106S=results/training/features/106S.parquet --out results/emulator"""
EXAMPLE_EMULATE_CV = """\
shockcal emulate-cv --emulator results/emulator --folds 5"""


def register(subparsers) -> None:
    p = add_command(subparsers, "emulate", example=EXAMPLE_EMULATE,
                    help="fit the emulator; write it and its cross-validation tables")
    add_config_argument(p)
    p.add_argument("--design", required=True, help="design table (CSV or Parquet, Table IV units)")
    p.add_argument("--features", required=True, nargs="+", metavar="SHOT=FILE",
                   help="per-shot feature tables (CSV or Parquet), joined to the design on `run`")
    p.add_argument("--shot-design", nargs="+", default=[], metavar="SHOT=FILE",
                   help="a shot whose runs have a design of their own (a new shot's, design.new_shots): its "
                        "features join that design, not --design's, and it gets an emulator block of its own")
    p.add_argument("--structure", choices=["per_shot", "joint"], help="override emulator.structure")
    p.add_argument("--first-runs", type=int, metavar="N",
                   help="fit on the design's first N rows only; the features of later runs are left out "
                        "(the next-shot check's emulators)")
    p.add_argument("--no-cv", action="store_true",
                   help="write the emulator only, no cross-validation tables (a sequential study's steps before the last)")
    p.add_argument("--out", required=True,
                   help="output directory (emulator.json, emulator.npz, cv.parquet, cv_heldout.parquet, cv_rmse.csv)")
    p.set_defaults(func=run)

    cv = add_command(subparsers, "emulate-cv", example=EXAMPLE_EMULATE_CV,
                     help="print the cross-validation table of a fitted emulator "
                                                  "(loo_closed_form, kfold, outer)")
    cv.add_argument("--emulator", required=True, help="emulator directory")
    cv.add_argument("--folds", type=int, help="recompute K-fold with this many folds (refits per fold)")
    cv.add_argument("--margin", type=float, help="recompute the outer check with this inner-box margin")
    cv.set_defaults(func=print_cv)


def run(args) -> int:
    import logging
    from dataclasses import replace
    from pathlib import Path

    from shockcal.emulator.study_emulator import fit_emulator
    from shockcal.io import read_table
    from shockcal.study.adapters import emulator_spec, inputs_read_by, load_study_design
    from shockcal.study.stages import load_stage_config

    config = load_stage_config(args.config, "emulate")
    paths = parse_pairs(args.features, "--features")
    own = parse_pairs(args.shot_design, "--shot-design")
    spec = replace(emulator_spec(config, list(paths)), own_blocks=tuple(own))
    if args.structure:
        spec = replace(spec, structure=args.structure)
    design = load_study_design(args.design, config, inputs_read_by(config, [s for s in paths if s not in own]))
    shot_designs = {shot: load_study_design(path, config, inputs_read_by(config, [shot])) for shot, path in own.items()}
    features = {shot: read_table(path) for shot, path in paths.items()}
    if args.first_runs is not None:
        from shockcal.errors import InputError

        if not 0 < args.first_runs <= len(design):
            raise InputError(f"--first-runs: {args.first_runs} is not between 1 and the design's {len(design)} rows "
                             f"({args.design})")
        design = design.iloc[:args.first_runs]
        features = {shot: table[table["run"].isin(design["run"])] if "run" in table else table
                    for shot, table in features.items()}
    emulator = fit_emulator(design, features, spec, sources=paths, shot_designs=shot_designs)
    out = Path(args.out)
    emulator.save(out)
    if args.no_cv:
        return 0
    settings = config["emulator"]
    table = write_cv(emulator, out, ["loo_closed_form", *HELD_OUT], settings["cv_folds"], settings["outer_margin"])
    logging.getLogger("shockcal.emulate").info("cross-validation (m/s):\n%s", table.to_string(index=False))
    return 0


def write_cv(emulator, out, schemes, folds: int, margin: float):
    """Write cv.parquet (closed-form LOO) and/or cv_heldout.parquet (K-fold, outer); return the RMSE table."""
    import pandas as pd

    from shockcal.emulator.study_emulator import rmse_table
    from shockcal.io import read_table, write_table

    if "loo_closed_form" in schemes:
        write_table(emulator.cv_table("loo_closed_form"), out / "cv.parquet",
                    {"table": "emulator closed-form leave-one-out (hyperparameters fixed: a fast diagnostic)",
                     "structure": emulator.structure, "units": UNITS})
    held = pd.concat([emulator.cv_table(s, folds=folds, margin=margin) for s in HELD_OUT], ignore_index=True)
    write_table(held, out / "cv_heldout.parquet",
                {"table": "emulator held-out predictions", "structure": emulator.structure, "units": UNITS,
                 "kfold": f"{folds} seeded folds, everything refitted per fold",
                 "outer": f"trained on scaled inputs in [{margin}, {1 - margin}], predicting the others"})
    table = rmse_table(pd.concat([read_table(out / "cv.parquet"), held], ignore_index=True))
    table.to_csv(out / "cv_rmse.csv", index=False)
    return table


def print_cv(args) -> int:
    from pathlib import Path

    import pandas as pd

    from shockcal.emulator.study_emulator import Emulator, rmse_table
    from shockcal.io import read_table

    out = Path(args.emulator)
    if args.folds is not None or args.margin is not None:
        margin = 0.05 if args.margin is None else args.margin
        table = write_cv(Emulator.load(out), out, HELD_OUT, args.folds or 10, margin)
    else:
        held = [read_table(out / "cv_heldout.parquet")] if (out / "cv_heldout.parquet").is_file() else []
        table = rmse_table(pd.concat([read_table(out / "cv.parquet"), *held], ignore_index=True))
    print(table.to_string(index=False))
    return 0
