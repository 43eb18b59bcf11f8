"""`shockcal calibrate` (posterior: equal-weight and weighted draws, summary), `shockcal calibrate-check`
(coverage on synthetic truth) and `shockcal coverage` (merging the check's batches).

calibrate reads the emulator directory and the observed features table and writes OUT (equal-weight
draws, native units), OUT_summary.parquet (in MPa, GPa and m/s) and OUT_weighted.parquet (the sampler's
weighted draws with their log weights: the exact result; `shockcal.inference.posterior_files`); config
keys: `calibration`, `observed.sd_fraction`, `checks.observed_units`, `inputs`, study.seed
(shockcal.study.stages declares them)."""

from __future__ import annotations

from shockcal.cli import add_command, add_config_argument, parse_pairs, parse_span, unique_shots

EXAMPLE_CALIBRATE = """\
shockcal calibrate --config config/config.yaml --emulator results/emulator --shots 104S 105S 106S \\
    --observed results/features/observed.parquet --out results/posterior/joint.parquet"""
EXAMPLE_CALIBRATE_CHECK = """\
shockcal calibrate-check --config config/config.yaml --emulator results/emulator --shots 104S \\
    --trials 10 --out results/check/104S_trials.parquet"""
EXAMPLE_COVERAGE = """\
shockcal coverage --trials results/check/coverage/emulator/batch-*.parquet \\
    --out results/posterior/coverage_emulator.parquet"""


def register(subparsers) -> None:
    p = add_command(subparsers, "calibrate", example=EXAMPLE_CALIBRATE,
                    help="posterior of the inputs given measured features (nested sampling)")
    add_config_argument(p)
    p.add_argument("--emulator", required=True, help="emulator directory (shockcal emulate --out)")
    p.add_argument("--shots", required=True, nargs="+", help="shots calibrated together (one = single-shot)")
    p.add_argument("--observed", required=True, help="observed features table (CSV or Parquet: shot + feature columns)")
    p.add_argument("--out", required=True, help="posterior samples (Parquet); the summary and the weighted draws go "
                                                 "beside it as *_summary.parquet and *_weighted.parquet")
    p.add_argument("--n-live", type=int, help="override calibration.n_live (live points)")
    p.add_argument("--n-eff", type=int, help="override calibration.n_eff (effective sample size to reach)")
    p.set_defaults(func=run)

    c = add_command(subparsers, "calibrate-check", example=EXAMPLE_CALIBRATE_CHECK,
                    help="coverage of 90%% intervals on synthetic truth (emulator or hydrocode)")
    add_config_argument(c)
    c.add_argument("--emulator", required=True)
    c.add_argument("--shots", required=True, nargs="+")
    c.add_argument("--out", required=True, help="coverage table (Parquet), one row per trial and parameter")
    trials = c.add_mutually_exclusive_group()
    trials.add_argument("--trials", type=int, help="override calibration.check.trials")
    trials.add_argument("--trial-range", metavar="START:STOP",
                        help="run trials START..STOP-1 only (a batch of the check; `shockcal coverage` merges them)")
    c.add_argument("--truth-design", help="hydrocode truth: design table of the truth runs (CSV or Parquet); alone, "
                                          "the truths are its inputs and the emulator draws their features")
    c.add_argument("--truth-features", nargs="+", metavar="SHOT=TABLE",
                   help="hydrocode truth: the features of the truth runs per shot (with --truth-design)")
    c.add_argument("--seed-stream", nargs="+", metavar="KEY",
                   help="the trials' seed stream of study.seed (default: check, the truth, the shots); calibrations "
                        "of other shots on one stream see the same noise on the shots they share")
    c.add_argument("--n-live", type=int, help="override calibration.check.n_live")
    c.add_argument("--n-eff", type=int, help="override calibration.check.n_eff (and the draws kept)")
    c.add_argument("--draws-out", help="also write every trial's equal-weight posterior draws (Parquet; trial, run)")
    c.set_defaults(func=run_check)

    m = add_command(subparsers, "coverage", example=EXAMPLE_COVERAGE,
                    help="merge per-trial tables of calibrate-check batches; print the coverage")
    m.add_argument("--trials", required=True, nargs="+", help="per-trial tables (calibrate-check --out)")
    m.add_argument("--out", required=True, help="merged per-trial table (Parquet)")
    m.add_argument("--against", nargs="+", metavar="TABLE",
                   help="another check's per-trial tables on the same truths (e.g. `calibrate-check --truth-design` "
                        "alone: the emulator's features there); the log adds the trial-by-trial comparison")
    m.set_defaults(func=run_coverage)


def study_emulator(directory, config: dict):
    """The emulator in `directory`, checked against the study's shot mappings and prior box
    (`Emulator.check_study`)."""
    from shockcal.emulator.study_emulator import Emulator
    from shockcal.study.adapters import shot_mapping
    from shockcal.study.config import prior_bounds

    emulator = Emulator.load(directory)
    emulator.check_study({shot: shot_mapping(config, shot).inputs() for shot in config["shots"]},
                         prior_bounds(config), f"emulator {directory}")
    return emulator


def sampler_overrides(settings, n_live: int | None, n_eff: int | None, draws_follow_n_eff: bool = False):
    """`settings` (CalibrationSettings) with the command line's --n-live and --n-eff (None: the config's;
    `draws_follow_n_eff`: keep n_eff draws too); InputError naming the option the sampler refuses."""
    from shockcal.errors import InputError

    for option, changes in (("--n-live", {"n_live": n_live}),
                            ("--n-eff", {"n_eff": n_eff, **({"draws": n_eff} if draws_follow_n_eff else {})})):
        if None in changes.values():
            continue
        try:
            settings = settings.with_sampler(**changes)
        except InputError as exc:
            raise InputError(f"{option}: {exc}") from None
    return settings


def run(args) -> int:
    import logging

    from shockcal.inference.calibration import calibrate
    from shockcal.inference.posterior_files import write_posterior
    from shockcal.io import read_table
    from shockcal.study.adapters import calibration_settings
    from shockcal.study.stages import load_stage_config

    config = load_stage_config(args.config, "calibrate")
    unique_shots(args.shots)
    emulator = study_emulator(args.emulator, config)
    observed = read_table(args.observed)
    settings = sampler_overrides(calibration_settings(config, args.shots), args.n_live, args.n_eff)
    posterior = calibrate(emulator, args.shots, observed, settings, source=args.observed)
    info = write_posterior(posterior, args.out)
    logging.getLogger("shockcal.calibrate").info(
        "posterior of %s (Kish ESS %.0f, %d draws written, %d distinct, %d likelihood evaluations, "
        "log evidence %.3f +- %.3f):\n%s", "+".join(args.shots), info["ess_kish"], len(posterior.draws),
        info["distinct_draws"], info["likelihood_evaluations"], info["log_evidence"], info["log_evidence_sd"],
        posterior.summary().to_string(index=False, float_format="%.4g"))
    if "discrepancy_parameters" in info:
        log_discrepancy(posterior, list(emulator.feature_names))
    return 0


def log_discrepancy(posterior, features: list[str]) -> None:
    """Log the discrepancy's sd per shot and feature in m/s at its posterior 5/50/95% points."""
    import logging

    from shockcal.inference.discrepancy import implied_sd_table
    from shockcal.inference.inference_data import observed_frames

    info = posterior.info()
    observed, _ = observed_frames(info["shots"], info["observed"], info["observed_sd_m_s"], features)
    logging.getLogger("shockcal.calibrate").info(
        "model discrepancy's sd (m/s) per shot and feature at its 5/50/95%% points (the sd fraction times the "
        "measured feature):\n%s", implied_sd_table(posterior.summary(), observed).to_string(index=False,
                                                                                           float_format="%.4g"))


def run_check(args) -> int:
    import logging

    from shockcal.errors import InputError
    from shockcal.inference.coverage import coverage_table, synthetic_truth
    from shockcal.io import write_table
    from shockcal.seeds import stream_seed
    from shockcal.study.adapters import calibration_settings
    from shockcal.study.stages import load_stage_config

    config = load_stage_config(args.config, "calibrate_check")
    unique_shots(args.shots)
    if not getattr(args, "verbose", False):   # the batch's progress line (count, time left) says enough; each trial's sampler lines: -v
        logging.getLogger("shockcal.inference.sampler").setLevel(logging.WARNING)
    truths = hydro_truths(args)
    emulator = study_emulator(args.emulator, config)
    truth = "emulator" if truths is None else "hydrocode" if truths.features is not None else "design-emulator"
    trials = trial_range(args.trial_range) or args.trials or config["calibration"]["check"]["trials"]
    stream = args.seed_stream or ["check", truth, *args.shots]
    try:
        seed = stream_seed(config["study"]["seed"], *stream)
    except ValueError as exc:
        raise InputError(f"--seed-stream: {exc}") from None
    draws = [] if args.draws_out else None
    settings = sampler_overrides(calibration_settings(config, args.shots, check=True), args.n_live, args.n_eff,
                                 draws_follow_n_eff=True)
    table = synthetic_truth(emulator, args.shots, settings, trials, seed=seed, truths=truths, draws=draws)
    source = ("emulator" if truths is None else f"hydrocode runs of {args.truth_design}" if truths.features is not None
              else f"the emulator at the inputs of {args.truth_design}")
    write_table(table, args.out, {"table": "synthetic-truth coverage", "shots": args.shots, "truth": source})
    if draws is not None:
        import pandas as pd

        if not draws:
            raise InputError(f"calibrate-check: no trial finished, no draws for {args.draws_out}")
        write_table(pd.concat(draws, ignore_index=True), args.draws_out,
                    {"table": "synthetic-truth posterior draws", "shots": args.shots, "truth": source})
    log_coverage(coverage_table(table), table)
    return 0


def run_coverage(args) -> int:
    import logging

    from shockcal.inference.coverage import coverage_table, paired_coverage
    from shockcal.io import read_tables, write_table

    table = read_tables(args.trials, ["trial", "parameter"], "per-trial")
    reference = None if not args.against else read_tables(args.against, ["trial", "parameter"], "per-trial")
    paired = None if reference is None else paired_coverage(table, reference)
    write_table(table, args.out, {"table": "synthetic-truth coverage", "batches": args.trials})
    log_coverage(coverage_table(table), table)
    if paired is not None:
        logging.getLogger("shockcal.calibrate").info(
            "trial by trial against %s (only_here / only_reference: trials one check alone covers; mcnemar_p: "
            "exact two-sided, small where the checks differ):\n%s", " ".join(args.against),
            paired.to_string(index=False, float_format="%.3f"))
    return 0


def log_coverage(coverage, trials) -> None:
    """Log the per-parameter coverage and, when the trials carry it, the joint check (`joint_coverage`)."""
    import logging

    from shockcal.inference.coverage import coverage_by_fifth, joint_coverage, usable_trials

    log = logging.getLogger("shockcal.calibrate")
    if "status" in trials:
        for trial, reason in trials[trials["status"] == "failed"].groupby("trial")["reason"].first().items():
            log.warning("trial %d failed and is left out: %s", trial, reason)
    log.info("coverage of nominal 90%% intervals:\n%s", coverage.to_string(index=False, float_format="%.3f"))
    log.info("coverage per fifth of each parameter's truths (lowest first):\n%s",
             coverage_by_fifth(trials).to_string(float_format="%.2f"))
    if "truth_hpd_mass" in trials and usable_trials(trials)["truth_hpd_mass"].notna().all():
        log.info("joint: truth in the 90%% highest-density region in %(coverage90).3f of %(trials)d trials "
                 "(band %(band_low).3f-%(band_high).3f); masses against uniform: KS p = %(uniform_ks_p).3g",
                 joint_coverage(trials))
    else:
        log.info("joint check: not available (trials from before the truth_hpd_mass column)")


def trial_range(text: str | None) -> range | None:
    """--trial-range START:STOP as the trial numbers START..STOP-1 (both given, START < STOP)."""
    from shockcal.errors import InputError

    if text is None:
        return None
    start, stop = parse_span(text, "--trial-range")
    if start is None or stop is None or not 0 <= start < stop:
        raise InputError(f"--trial-range: '{text}' is not START:STOP with 0 <= START < STOP")
    return range(start, stop)


def hydro_truths(args):
    """The hydrocode truth runs named on the command line, or None (emulator truth)."""
    from shockcal.errors import InputError
    from shockcal.inference.coverage import HydroTruths

    if not args.truth_design and not args.truth_features:
        return None
    if not args.truth_design:
        raise InputError("calibrate-check: --truth-features needs --truth-design (the truth runs' inputs)")
    features = None if not args.truth_features else parse_pairs(args.truth_features, "--truth-features")
    return HydroTruths.read(args.truth_design, features, args.shots)
