"""`shockcal next-shot-design` and `shockcal suggest-shot`: which shot next (docs/next_shot.md).

next-shot-design reads the joint posterior's equal-weight draws and writes one candidate's design
(`shockcal.campaign.candidates.candidate_design`: next_shot.n_draws draws, stream next_shot "draws", the same rows
for every candidate), after checking that the candidate's waves split (`check_split`); its runs go
through `shockcal simulate --candidate` and `shockcal features --candidate`.
suggest-shot reads every candidate's design and features and writes the ranking (CSV): per candidate
the expected information gain about next_shot.targets (noise: observed.sd_fraction of each feature,
with the extractor's read-out sd and, with next_shot.emulator_error, the emulator's K-fold RMSE of the
reference shot's features, in quadrature; the read-out sd of a feature is next_shot.readout_sd_m_s's
value where given, else the reference shot's `readout_sd_<feature>` in the observed table), its
bootstrap sd, the full-theta bracket,
each target's marginal gain and expected posterior sd, the features' spread against the measurement
noise. Config keys: next_shot, observed.sd_fraction, study.seed, inputs.
"""

from __future__ import annotations

from shockcal.cli import add_command, add_config_argument, parse_pairs

EXAMPLE_NEXT_SHOT_DESIGN = """\
shockcal next-shot-design --config config/config.yaml --candidate 104S-repeat \\
    --posterior results/posterior/joint.parquet --out results/104S-repeat/design.parquet"""
EXAMPLE_SUGGEST_SHOT = """\
shockcal suggest-shot --config config/config.yaml \\
    --designs 104S-repeat=results/104S-repeat/design.parquet 105S-repeat=results/105S-repeat/design.parquet \\
    --features 104S-repeat=results/104S-repeat/features/104S-repeat.parquet \\
    105S-repeat=results/105S-repeat/features/105S-repeat.parquet --out results/next_shot/ranking.csv"""


def register(subparsers) -> None:
    d = add_command(subparsers, "next-shot-design", example=EXAMPLE_NEXT_SHOT_DESIGN,
                    help="a next-shot candidate's design: joint-posterior draws at its conditions")
    add_config_argument(d)
    d.add_argument("--candidate", required=True, help="candidate name (next_shot.candidates)")
    d.add_argument("--posterior", required=True, help="the joint posterior's equal-weight draws (Parquet or CSV)")
    d.add_argument("--out", required=True, help="output Parquet design of the candidate's runs")
    d.set_defaults(func=run_design)

    s = add_command(subparsers, "suggest-shot", example=EXAMPLE_SUGGEST_SHOT,
                    help="rank the next-shot candidates by expected information gain")
    add_config_argument(s)
    s.add_argument("--designs", nargs="+", required=True, help="CANDIDATE=DESIGN pairs (next-shot-design's tables)")
    s.add_argument("--features", nargs="+", required=True, help="CANDIDATE=FEATURES pairs (their runs' features)")
    s.add_argument("--emulator-rmse", help="the emulator's cross-validation RMSE table (emulator/cv_rmse.csv), "
                   "needed with next_shot.emulator_error")
    s.add_argument("--observed", help="the measured features (features/observed.parquet): each candidate's "
                   "read-out sd is its reference shot's readout_sd_<feature> where next_shot.readout_sd_m_s "
                   "gives none; without it such a feature's read-out sd is 0")
    s.add_argument("--out", required=True, help="output ranking CSV (results/next_shot/ranking.csv)")
    s.set_defaults(func=run_suggest)


def run_design(args) -> int:
    import logging

    from shockcal.campaign.candidates import candidate_design, check_split
    from shockcal.errors import InputError
    from shockcal.io import read_table, read_table_metadata, write_table
    from shockcal.seeds import stream_seed
    from shockcal.study.adapters import candidate, material_properties
    from shockcal.study.config import input_names, prior_bounds
    from shockcal.study.stages import load_stage_config

    config = load_stage_config(args.config, "next_shot_design", args.candidate)
    shot = candidate(config, args.candidate)
    posterior = read_table(args.posterior)
    shots = read_table_metadata(args.posterior).get("shots") if args.posterior.endswith((".parquet", ".pq")) else None
    if shots is not None and sorted(shots) != sorted(config["shots"]):
        raise InputError(f"{args.posterior}: a posterior of shots {shots}; the next shot's prior is the joint "
                         f"posterior of the config's shots {sorted(config['shots'])}")
    section, material = config["next_shot"], material_properties(config)
    slope = section["shear_modulus_log_slope_per_K"]
    seed = stream_seed(config["study"]["seed"], "next_shot", "draws")
    design = candidate_design(posterior, input_names(config), shot, section["n_draws"], seed, material,
                              section["velocity_sd_fraction"], (slope["min"], slope["max"]), prior_bounds(config),
                              args.posterior)
    check_split(design, shot, material, f"next_shot.candidates.{args.candidate}")
    units = {name: config["inputs"][name]["unit"] for name in input_names(config)}
    write_table(design, args.out, {"table": "design", "candidate": args.candidate,
                                   "source": f"joint posterior draws from {args.posterior}, seed {seed}",
                                   "units": {**units, "velocity_cm_us": "cm/us", "shear_modulus_Mbar": "Mbar",
                                             "shear_modulus_log_slope_per_K": "1/K"}})
    logging.getLogger("shockcal.campaign.next_shot").info("candidate %s: %d posterior draws (seed %d) -> %s", args.candidate,
                                                 len(design), seed, args.out)
    return 0


def emulator_rmse(table, shot: str, features, source: str):
    """The emulator's K-fold RMSE (m/s) of `shot`'s `features`, from its cv_rmse table; a missing row is an
    InputError naming the table."""

    from shockcal.errors import InputError
    from shockcal.io import require_columns

    require_columns(table, ["scheme", "shot", "feature", "rmse_m_s"], source)
    rows = table[(table["scheme"] == "kfold") & (table["shot"].astype(str) == shot)].set_index("feature")
    missing = [f for f in features if f not in rows.index]
    if missing:
        raise InputError(f"{source}: no kfold RMSE of shot {shot}'s {', '.join(missing)} (a candidate's reference "
                         "shot): an emulator of other shots?")
    return rows.loc[list(features), "rmse_m_s"].to_numpy(dtype=float)


def candidate_readout_sd(given: dict, observed, shot: str, features, source: str):
    """A candidate's read-out sd per feature (m/s): next_shot.readout_sd_m_s's value where `given` has the
    feature, else the reference `shot`'s `readout_sd_<feature>` in the `observed` table (a candidate has no
    record yet; its reference shot's read-out error is the cautious stand-in), else 0 (no table, or a
    table without read-out columns: a published one)."""

    import numpy as np

    from shockcal.errors import InputError
    from shockcal.inference.problem import readout_vector

    if observed is None:
        reference = np.zeros(len(features))
    elif shot not in set(observed["shot"].astype(str).str.strip()):
        raise InputError(f"{source}: no row for shot {shot} (a candidate's reference shot)")
    else:
        reference = readout_vector(observed, [shot], list(features), source)
    return np.array([given.get(f, r) for f, r in zip(features, reference)], dtype=float)


def run_suggest(args) -> int:
    import logging
    from pathlib import Path

    import numpy as np

    from shockcal.campaign.candidates import SLOPE, VELOCITY_FACTOR, check_design, ranking_table, score_candidate
    from shockcal.errors import InputError
    from shockcal.io import atomic_path, read_table
    from shockcal.seeds import stream_seed
    from shockcal.study.config import input_names
    from shockcal.study.stages import load_stage_config
    from shockcal.study.strength_config import next_shot_targets
    from shockcal.velocimetry.columns import CALIBRATION_FEATURES

    config = load_stage_config(args.config, "suggest_shot")
    section = config["next_shot"]
    designs, features = parse_pairs(args.designs, "--designs"), parse_pairs(args.features, "--features")
    for option, given in (("--designs", designs), ("--features", features)):
        missing = [name for name in section["candidates"] if name not in given]
        unknown = [name for name in given if name not in section["candidates"]]
        if missing or unknown:
            raise InputError(f"{option}: " + (f"no table for candidate(s) {missing}" if missing else
                                              f"{unknown} are not candidates of next_shot.candidates"))
    names = input_names(config)
    parameters = [*names, VELOCITY_FACTOR, SLOPE]
    observed = read_table(args.observed) if args.observed else None
    if section["emulator_error"] and not args.emulator_rmse:
        raise InputError("next_shot.emulator_error is true: give the emulator's RMSE table (--emulator-rmse "
                         "results/emulator/cv_rmse.csv), or set it to false")
    rmse = read_table(args.emulator_rmse) if section["emulator_error"] else None
    log = logging.getLogger("shockcal.campaign.next_shot")
    targets = next_shot_targets(config)
    rows = []
    for name, spec in section["candidates"].items():
        design = check_design(read_table(designs[name]), names, designs[name])
        model = (np.zeros(len(CALIBRATION_FEATURES)) if rmse is None else
                 emulator_rmse(rmse, spec["shot"], CALIBRATION_FEATURES, args.emulator_rmse))
        readout = candidate_readout_sd(section["readout_sd_m_s"], observed, spec["shot"], CALIBRATION_FEATURES,
                                       args.observed)
        try:
            score = score_candidate(read_table(features[name]), design, CALIBRATION_FEATURES, parameters,
                                    targets, config["observed"]["sd_fraction"], np.hypot(readout, model),
                                    stream_seed(config["study"]["seed"], "next_shot", "eig", name))
        except InputError as exc:
            raise InputError(f"candidate {name} ({features[name]}): {exc}") from None
        temperature = spec.get("initial_temperature_K") or config["material"]["T_ref_K"]
        rows.append({"candidate": name, "flyer_mm": spec["flyer_mm"], "target_mm": spec["target_mm"],
                     "velocity_m_s": spec["velocity_m_s"], "initial_temperature_K": temperature, **score})
        log.info("candidate %s: EIG %.3f +- %.3f nats (%d draws, %d failed)", name, score["eig_nats"],
                 score["eig_sd"], score["n_draws"], score["n_failed"])
    table = ranking_table(rows)
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    with atomic_path(args.out) as tmp:
        table.to_csv(tmp, index=False, float_format="%.6g")
    log.info("ranking (targets %s):\n%s", ", ".join(targets),
             table[["rank", "candidate", "eig_nats", "eig_sd", "overlaps_best"]].to_string(index=False))
    return 0
