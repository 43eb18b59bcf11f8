"""`shockcal predict` (joint-posterior draws as a design for hydrocode runs) and `shockcal predict-emulator`."""

from __future__ import annotations

from shockcal.cli import add_command, add_config_argument

EXAMPLE_PREDICT = """\
shockcal predict --config config/config.yaml --posterior results/posterior/joint.parquet \\
    --out results/predict/design.parquet"""
EXAMPLE_PREDICT_EMULATOR = """\
shockcal predict-emulator --config config/config.yaml --design results/predict/design.parquet \\
    --emulator results/emulator --out results/predict/emulator.parquet"""

# a stream of joint-posterior draws (shockcal.seeds): the stage whose config slice the command reads, and the key
# that sets how many draws it takes: the predictive runs, the posterior-truth check's truths, `make verify`'s draws
DRAW_STREAMS = {"posterior_draws": ("predict", ("predict", "n_posterior_runs")),
                "check_posterior": ("check_posterior_design", ("calibration", "check", "trials")),
                "verify": ("verify_design", ("verify", "n_draws"))}


def register(subparsers) -> None:
    p = add_command(subparsers, "predict", example=EXAMPLE_PREDICT,
                    help="draw joint-posterior samples as a design table for hydrocode runs")
    add_config_argument(p)
    p.add_argument("--posterior", required=True, help="joint posterior samples (Parquet or CSV)")
    p.add_argument("--out", required=True, help="output Parquet design table of the drawn samples")
    p.add_argument("--n-runs", type=int, default=None, help="override the stream's number of draws")
    p.add_argument("--seed", type=int, default=None, help="override the seed (default: the study's --stream)")
    p.add_argument("--stream", default="posterior_draws",
                   help="what the draws are for, which seeds them from the study's seed and sets their number: "
                        + "; ".join(f"{stream}: {'.'.join(key)}" for stream, (_, key) in DRAW_STREAMS.items()))
    p.set_defaults(func=run)

    e = add_command(subparsers, "predict-emulator", example=EXAMPLE_PREDICT_EMULATOR,
                    help="emulator predictions of the features at a design's rows")
    add_config_argument(e)
    e.add_argument("--design", required=True, help="design table, e.g. the posterior draws of `shockcal predict`")
    e.add_argument("--emulator", required=True, help="emulator directory written by `shockcal emulate`")
    e.add_argument("--out", required=True, help="output Parquet table: run, shot, features and their sd (m/s)")
    e.set_defaults(func=run_emulator)


def run(args) -> int:
    import logging
    import operator
    from functools import reduce

    from shockcal.design.posterior_draws import draw_posterior_design
    from shockcal.errors import InputError
    from shockcal.inference.discrepancy import is_discrepancy_parameter
    from shockcal.inference.problem import LAMBDA_Y
    from shockcal.io import read_table, read_table_metadata, write_table
    from shockcal.seeds import stream_seed
    from shockcal.study.config import input_names, prior_bounds
    from shockcal.study.stages import load_stage_config

    if args.stream not in DRAW_STREAMS:
        raise InputError(f"--stream: {args.stream!r} is not a stream of posterior draws ({', '.join(DRAW_STREAMS)})")
    stage, count_key = DRAW_STREAMS[args.stream]
    config = load_stage_config(args.config, stage)
    n_runs = args.n_runs or reduce(operator.getitem, count_key, config)
    seed = stream_seed(config["study"]["seed"], args.stream) if args.seed is None else args.seed
    posterior = read_table(args.posterior)
    shots = read_table_metadata(args.posterior).get("shots") if args.posterior.endswith((".parquet", ".pq")) else None
    if shots is not None and sorted(shots) != sorted(config["shots"]):
        raise InputError(f"{args.posterior}: a posterior of shots {shots}; predict draws from the joint posterior of the "
                         f"config's shots {sorted(config['shots'])}")
    discrepancy = tuple(name for name in posterior.columns if is_discrepancy_parameter(name))   # none: ()
    design = draw_posterior_design(posterior, input_names(config), n_runs, seed, source=args.posterior,
                                   bounds=prior_bounds(config), carried=(LAMBDA_Y, *discrepancy))
    units = {name: config["inputs"].get(name, {"unit": "-"})["unit"] for name in design.columns if name != "run"}
    write_table(design, args.out, {"table": "design", "source": f"posterior draws from {args.posterior}, seed {seed}",
                                   "units": units})
    logging.getLogger("shockcal.inference.predict").info("wrote %d posterior draws (seed %d) to %s", len(design), seed, args.out)
    return 0


def run_emulator(args) -> int:
    import logging

    from shockcal.cli.calibrate import study_emulator
    from shockcal.inference.predict import emulator_predictions
    from shockcal.io import write_table
    from shockcal.study.adapters import load_study_design
    from shockcal.study.stages import load_stage_config

    config = load_stage_config(args.config, "emulate_predict")
    emulator = study_emulator(args.emulator, config)
    shots = [s for s in config["shots"] if s in emulator.shots]
    design = load_study_design(args.design, config)
    emulator.check_inside(design, args.design)
    table = emulator_predictions(emulator, design, shots)
    write_table(table, args.out, {"table": "emulator_predictions", "design": args.design, "emulator": args.emulator,
                                  "units": "m/s"})
    logging.getLogger("shockcal.inference.predict").info("wrote emulator predictions for %d runs x %d shots to %s",
                                               len(design), len(shots), args.out)
    return 0
