"""`shockcal wave-design` (a later wave's design from the previous wave's joint posterior),
`shockcal new-shot-design` (a new shot's runs from the base shots' joint posterior) and
`shockcal merge-runs` (every run of a sequential study so far, as one design and one features table per
shot): docs/sequential.md. Config keys: `design.waves`, `inputs`, study.seed (shockcal.study.stages)."""

from __future__ import annotations

from shockcal.cli import add_command, add_config_argument

EXAMPLE_WAVE_DESIGN = """\
shockcal wave-design --config config/sequential.yaml --wave 2 \\
    --posterior results/sequential/waves/step1/posterior/joint.parquet \\
    --earlier-summary results/sequential/waves/step0/posterior/joint_summary.parquet \\
    --previous-design results/sequential/wave1/design.parquet --runs results/sequential/waves/step1/design.parquet \\
    --out results/sequential/wave2/design.parquet"""
EXAMPLE_MERGE_RUNS = """\
shockcal merge-runs --config config/sequential.yaml \\
    --designs results/sequential/training/design.parquet results/sequential/wave1/design.parquet \\
    --features 104S=results/sequential/training/features/104S.parquet 104S=results/sequential/wave1/features/104S.parquet \\
    --out results/sequential/waves/step1"""

EXAMPLE_NEW_SHOT_DESIGN = """\
shockcal new-shot-design --config config/config.yaml --shot 107S \\
    --posterior results/waves/step0/posterior/joint.parquet --runs results/waves/step0/design.parquet \\
    --out results/new_shot/designs/107S.parquet"""


def register(subparsers) -> None:
    w = add_command(subparsers, "wave-design", help="a later wave's design: the previous joint posterior thinned",
                    example=EXAMPLE_WAVE_DESIGN)
    add_config_argument(w)
    w.add_argument("--wave", required=True, type=int, help="the wave's number (1 for the first after wave 0)")
    w.add_argument("--posterior", required=True,
                   help="the previous wave's joint posterior samples (its summary beside it: *_summary.parquet)")
    w.add_argument("--earlier-summary",
                   help="the joint posterior summary of the wave before the previous one (the stopping rule)")
    w.add_argument("--previous-design", required=True,
                   help="the previous wave's design: when it is empty (the study stopped), so is this one")
    w.add_argument("--runs", required=True, help="every run so far (merge-runs' design.parquet)")
    w.add_argument("--emulator", help="the previous wave's emulator directory (criterion max_variance)")
    w.add_argument("--observed", help="the observed features table (criterion max_variance)")
    w.add_argument("--out", required=True, help="the wave's design table (Parquet)")
    w.set_defaults(func=run_wave_design)

    n = add_command(subparsers, "new-shot-design", example=EXAMPLE_NEW_SHOT_DESIGN,
                    help="a new shot's design: the base shots' joint posterior thinned, its own inputs drawn fresh")
    add_config_argument(n)
    n.add_argument("--shot", required=True, help="the new shot (a shot outside design.base_shots)")
    n.add_argument("--posterior", required=True, help="the base shots' joint posterior samples")
    n.add_argument("--runs", required=True, help="the base shots' runs (their design): the new rows keep away "
                                                 "from them, and their ids follow the largest")
    n.add_argument("--out", required=True, help="the shot's design table (Parquet)")
    n.set_defaults(func=run_new_shot_design)

    m = add_command(subparsers, "merge-runs", help="designs and features of several run sets as one of each",
                    example=EXAMPLE_MERGE_RUNS)
    add_config_argument(m)
    m.add_argument("--designs", required=True, nargs="+", help="design tables (run ids unique over all of them)")
    m.add_argument("--features", required=True, nargs="+", metavar="SHOT=FILE",
                   help="features tables, a shot's tables each given as SHOT=FILE")
    m.add_argument("--out", required=True, help="directory: design.parquet and features/SHOT.parquet")
    m.set_defaults(func=run_merge)


def run_wave_design(args) -> int:
    import logging

    from shockcal.design.settings import WaveSettings
    from shockcal.design.waves import wave_design
    from shockcal.errors import InputError
    from shockcal.inference.posterior_files import companion_path
    from shockcal.inference.summaries import posterior_settled, quantile_shifts
    from shockcal.io import read_table, write_table
    from shockcal.seeds import stream_seed
    from shockcal.study.adapters import load_study_design
    from shockcal.study.config import prior_bounds, user_box_widths
    from shockcal.study.stages import load_stage_config

    log = logging.getLogger("shockcal.design.waves")
    config = load_stage_config(args.config, "wave_design")
    if config["design"]["strategy"] != "waves":
        raise InputError(f"wave-design: design.strategy is {config['design']['strategy']!r}; waves need 'waves'")
    waves = WaveSettings.from_section(config["design"]["waves"])
    sizes = waves.sizes()
    if not 1 <= args.wave < len(sizes):
        raise InputError(f"--wave: {args.wave} is not a later wave of this study (1 to {len(sizes) - 1})")
    n_runs, stopped = sizes[args.wave], ""
    posterior = read_table(args.posterior)
    # the inputs of the calibrated shots: a new shot's own (design.new_shots) are not in the posterior, nor drawn
    bounds = {name: box for name, box in prior_bounds(config).items() if name in posterior.columns}
    if load_study_design(args.previous_design, config, list(bounds), allow_empty=True).empty:
        stopped = f"the previous wave ({args.previous_design}) is empty: the study stopped before it"
    elif args.earlier_summary:
        before, after = read_table(args.earlier_summary), read_table(companion_path(args.posterior))
        shifts = quantile_shifts(before, after)
        log.info("joint posterior's 5/50/95%% points moved (combined Monte Carlo SE):\n%s",
                 shifts.to_string(index=False, float_format="%.2f"))
        if posterior_settled(before, after, waves.stop_mcse, user_box_widths(config), waves.stop_box):
            stopped = (f"no 5/50/95% point moved by max({waves.stop_mcse:g} combined Monte Carlo SE, "
                       f"{waves.stop_box:g} of its box) or more (design.waves.stop_mcse, stop_box)")
    runs = load_study_design(args.runs, config, list(bounds))
    variance = None
    if waves.criterion == "max_variance" and not stopped:
        variance = max_variance_score(args, config)
    design = wave_design(posterior, bounds, 0 if stopped else n_runs,
                         int(runs["run"].max()) + 1, stream_seed(config["study"]["seed"], "waves", "pool", args.wave),
                         existing=runs, widen=waves.widen, pool_size=waves.pool_size,
                         criterion=waves.criterion, variance=variance, source=args.posterior)
    units = {name: config["inputs"][name]["unit"] for name in design.columns if name != "run"}
    write_table(design, args.out, {"table": "design", "units": units, "stopped": stopped,
                                   "source": f"wave {args.wave}: {waves.criterion} from {args.posterior}"})
    log.info("wave %d: %s", args.wave, f"stopped, no runs: {stopped}" if stopped else
             f"{len(design)} runs (ids {design['run'].min()}-{design['run'].max()}) -> {args.out}")
    return 0


def run_new_shot_design(args) -> int:
    import logging

    from shockcal.design.settings import WaveSettings
    from shockcal.design.waves import new_shot_design
    from shockcal.errors import InputError
    from shockcal.io import read_table, write_table
    from shockcal.seeds import stream_seed
    from shockcal.study.adapters import base_inputs, inputs_read_by, load_study_design
    from shockcal.study.config import prior_bounds
    from shockcal.study.stages import load_stage_config

    config = load_stage_config(args.config, "new_shot_design", shot=args.shot)
    design_section = config["design"]
    if not design_section["base_shots"] or args.shot in design_section["base_shots"]:
        raise InputError(f"--shot: {args.shot} is not a new shot: design.base_shots is "
                         f"{design_section['base_shots']}")
    base = base_inputs(config)
    own = [name for name in inputs_read_by(config, [args.shot]) if name not in base]
    runs = load_study_design(args.runs, config, base)
    bounds, seed, section = prior_bounds(config), config["study"]["seed"], design_section["new_shots"]
    waves = WaveSettings.from_section(design_section["waves"])
    design = new_shot_design(read_table(args.posterior), {n: bounds[n] for n in base}, {n: bounds[n] for n in own},
                             section["n_runs"], int(runs["run"].max()) + 1, stream_seed(seed, "new_shot", args.shot),
                             {n: stream_seed(seed, "new_shot", args.shot, n) for n in own}, existing=runs,
                             widen=waves.widen, pool_size=waves.pool_size,
                             source=args.posterior)
    units = {name: config["inputs"][name]["unit"] for name in design.columns if name != "run"}
    write_table(design, args.out, {"table": "design", "units": units, "shot": args.shot,
                                   "source": f"new shot {args.shot}: posterior_thinned from {args.posterior}"})
    logging.getLogger("shockcal.design.waves").info(
        "new shot %s: %d runs (ids %d-%d; %s drawn fresh) -> %s", args.shot, len(design), design["run"].min(),
        design["run"].max(), ", ".join(own) or "no input of its own", args.out)
    return 0


def max_variance_score(args, config):
    """The max_variance criterion's score of a candidate table: the previous emulator's predictive
    variance over the observation variance (`relative_variance`), summed over its shots' features."""
    import numpy as np

    from shockcal.cli.calibrate import study_emulator
    from shockcal.design.waves import relative_variance
    from shockcal.errors import InputError
    from shockcal.io import read_table
    from shockcal.velocimetry.columns import CALIBRATION_FEATURES

    if not args.emulator or not args.observed:
        raise InputError("wave-design: design.waves.criterion max_variance needs --emulator and --observed")
    emulator, observed = study_emulator(args.emulator, config), read_table(args.observed).set_index("shot")
    shots = emulator.shots
    sd = np.concatenate([config["observed"]["sd_fraction"] * observed.loc[s, CALIBRATION_FEATURES].to_numpy(float)
                         for s in shots])
    return lambda pool: relative_variance(emulator, pool, shots, sd)


def run_merge(args) -> int:
    import logging
    from pathlib import Path

    import pandas as pd

    from shockcal.errors import InputError
    from shockcal.io import read_table, read_tables, write_table
    from shockcal.study.adapters import inputs_read_by, load_study_design
    from shockcal.study.stages import load_stage_config

    config = load_stage_config(args.config, "merge_runs")
    by_shot: dict[str, list[str]] = {}
    for pair in args.features:
        shot, sep, path = pair.partition("=")
        if not sep or not shot or not path:
            raise InputError(f"--features: '{pair}' is not SHOT=FILE")
        by_shot.setdefault(shot, []).append(path)
    read = inputs_read_by(config, by_shot)
    designs = [load_study_design(path, config, read, allow_empty=True) for path in args.designs]
    design = pd.concat(designs, ignore_index=True)
    if design["run"].duplicated().any():
        run = design.loc[design["run"].duplicated(), "run"].iloc[0]
        raise InputError(f"run id {run} is in more than one of the designs {' '.join(args.designs)}")
    out = Path(args.out)
    write_table(design, out / "design.parquet", {"table": "design", "source": f"merged from {' '.join(args.designs)}",
                                                 "units": {k: config["inputs"][k]["unit"] for k in config["inputs"]}})
    for shot, paths in by_shot.items():
        with_runs = [path for path in paths if not read_table(path).empty]     # a stopped wave's table has none
        table = read_tables(with_runs or paths[:1], ["run"], "features")
        write_table(table, out / "features" / f"{shot}.parquet", {"table": "features", "shot": shot,
                                                                  "merged": paths})
    logging.getLogger("shockcal.design.waves").info("%d runs of %d designs -> %s", len(design), len(designs), out)
    return 0
