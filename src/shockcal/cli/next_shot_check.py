"""`shockcal next-shot-check-truths` and `shockcal next-shot-check-summary`: the realized check of the
next-shot ranking (docs/next_shot.md "The realized check").

next-shot-check-truths draws next_shot.check.n_truths rows of the joint posterior (stream next_shot
"check_truths") as the truths of every compared candidate (`shockcal.campaign.ranking_check.truth_design`): the
study's inputs, lambda_y, and each candidate's velocity and shear-modulus increment as its fourth shot
reads them (`shockcal.study.candidate_studies`). Their runs go through `shockcal simulate` and `features`,
their calibrations through `shockcal calibrate-check --truth-design ... --draws-out`.
next-shot-check-summary reads the calibrations' draws and the ranking and writes the per-truth table
(check.csv) and the summary with the verdict (check_summary.csv). Config keys: study.seed, next_shot,
inputs, material, the shots' plates, moduli and windows.
"""

from __future__ import annotations

from shockcal.cli import add_command, add_config_argument, parse_pairs

EXAMPLE_NEXT_SHOT_CHECK_TRUTHS = """\
shockcal next-shot-check-truths --config config/config.yaml --posterior results/posterior/joint.parquet \\
    --candidates 104S-repeat 106S-repeat --out results/next_shot_truth/design.parquet \\
    --candidate-designs 104S-repeat=results/next_shot_truth/designs/104S-repeat.parquet \\
    106S-repeat=results/next_shot_truth/designs/106S-repeat.parquet"""
EXAMPLE_NEXT_SHOT_CHECK_SUMMARY = """\
shockcal next-shot-check-summary --config config/config.yaml --ranking results/next_shot/ranking.csv \\
    --posterior results/posterior/joint.parquet --baseline results/next_shot/check/baseline/draws.parquet \\
    --candidates 104S-repeat=results/next_shot/check/104S-repeat/draws.parquet \\
    106S-repeat=results/next_shot/check/106S-repeat/draws.parquet --out results/next_shot/check.csv"""


def register(subparsers) -> None:
    t = add_command(subparsers, "next-shot-check-truths", example=EXAMPLE_NEXT_SHOT_CHECK_TRUTHS,
                    help="the next-shot check's truths: joint-posterior draws with each candidate's inputs")
    add_config_argument(t)
    t.add_argument("--posterior", required=True, help="the joint posterior's equal-weight draws (Parquet or CSV)")
    t.add_argument("--candidates", required=True, nargs="+", help="the compared candidates (next_shot.candidates)")
    t.add_argument("--out", required=True, help="output Parquet design of the truth runs (the study's inputs, "
                                                 "lambda_y, each candidate's inputs as its fourth shot reads them)")
    t.add_argument("--candidate-designs", required=True, nargs="+", metavar="CANDIDATE=DESIGN",
                   help="output Parquet design of each candidate's truth runs (the columns a candidate's runs read)")
    t.set_defaults(func=run_truths)

    s = add_command(subparsers, "next-shot-check-summary", example=EXAMPLE_NEXT_SHOT_CHECK_SUMMARY,
                    help="the next-shot check's realized gains and sds against the ranking's prediction")
    add_config_argument(s)
    s.add_argument("--ranking", required=True, help="the ranking (results/next_shot/ranking.csv)")
    s.add_argument("--posterior", required=True, help="the joint posterior's equal-weight draws (the scores' marginals)")
    s.add_argument("--baseline", required=True, help="the three-shot calibrations' draws (calibrate-check --draws-out)")
    s.add_argument("--candidates", required=True, nargs=2, metavar="CANDIDATE=DRAWS",
                   help="each compared candidate's four-shot calibrations' draws")
    s.add_argument("--out", required=True, help="output per-truth table (CSV); the summary goes beside it as "
                                                 "<out>_summary.csv")
    s.set_defaults(func=run_summary)


def run_truths(args) -> int:
    import logging

    from shockcal.campaign.ranking_check import truth_design
    from shockcal.errors import InputError
    from shockcal.inference.problem import LAMBDA_Y
    from shockcal.io import read_table, write_table
    from shockcal.seeds import stream_seed
    from shockcal.study.adapters import candidate, material_properties
    from shockcal.study.candidate_studies import check_inputs
    from shockcal.study.config import input_names, prior_bounds
    from shockcal.study.stages import load_stage_config

    config = load_stage_config(args.config, "next_shot_check_truths")
    section = config["next_shot"]
    candidates = {name: (candidate(config, name), *check_inputs(config, name)) for name in args.candidates}
    seed = stream_seed(config["study"]["seed"], "next_shot", "check_truths")
    slope = section["shear_modulus_log_slope_per_K"]
    outputs = parse_pairs(args.candidate_designs, "--candidate-designs")
    if sorted(outputs) != sorted(candidates):
        raise InputError(f"--candidate-designs: give one for each of --candidates {args.candidates}, not {sorted(outputs)}")
    design, designs = truth_design(read_table(args.posterior), input_names(config), candidates,
                                   section["check"]["n_truths"], seed, material_properties(config),
                                   section["velocity_sd_fraction"], (slope["min"], slope["max"]), prior_bounds(config),
                                   args.posterior)
    for name, path in outputs.items():
        write_table(designs[name], path, {"table": "design", "candidate": name, "run_set": "next-shot check truths",
                                          "source": f"joint posterior draws from {args.posterior}, seed {seed}"})
    units = {**{name: config["inputs"][name]["unit"] for name in input_names(config)}, LAMBDA_Y: "-",
             **{velocity: "cm/us" for _, velocity, _ in candidates.values()},
             **{increment: "Mbar" for _, _, increment in candidates.values() if increment}}
    write_table(design, args.out, {"table": "design", "run_set": "next-shot check truths", "units": units,
                                   "source": f"joint posterior draws from {args.posterior}, seed {seed}"})
    logging.getLogger("shockcal.campaign.next_shot").info("next-shot check: %d truths (seed %d) for %s -> %s", len(design), seed,
                                                 ", ".join(args.candidates), args.out)
    return 0


def run_summary(args) -> int:
    import logging
    from pathlib import Path

    import pandas as pd

    from shockcal.campaign.ranking_check import check_summary, check_table
    from shockcal.errors import InputError
    from shockcal.io import atomic_path, read_table, require_columns
    from shockcal.study.stages import load_stage_config
    from shockcal.study.strength_config import next_shot_targets

    config = load_stage_config(args.config, "next_shot_check_summary")
    targets = next_shot_targets(config)
    ranking = pd.read_csv(args.ranking) if Path(args.ranking).is_file() else None
    if ranking is None:
        raise InputError(f"{args.ranking}: missing: run `make next-shot` first")
    require_columns(ranking, ["candidate", "eig_nats", *(f"{k}_sd_{p}" for k in ("prior", "expected") for p in targets)],
                    args.ranking)
    pairs = parse_pairs(args.candidates, "--candidates")
    tables = {}
    for name, path in [("baseline", args.baseline), *pairs.items()]:
        tables[name] = read_table(path)
        require_columns(tables[name], ["run", *targets], path)
    ranked = ranking.set_index("candidate")
    unknown = [name for name in pairs if name not in ranked.index]
    if unknown:
        raise InputError(f"{args.ranking}: no row of candidate(s) {unknown}")
    best, worst = sorted(pairs, key=lambda name: -ranked.loc[name, "eig_nats"])
    check = check_table(read_table(args.posterior), tables.pop("baseline"), tables, targets)
    summary = check_summary(check, ranking, best, worst, targets, args.ranking)
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    for table, path in ((check, out), (summary, out.with_name(f"{out.stem}_summary.csv"))):
        with atomic_path(path) as tmp:
            table.to_csv(tmp, index=False, float_format="%.6g")
    logging.getLogger("shockcal.campaign.next_shot").info("next-shot check, %s against %s over %d truths:\n%s", best, worst,
                                                 check["run"].nunique(), summary.to_string(index=False))
    return 0
