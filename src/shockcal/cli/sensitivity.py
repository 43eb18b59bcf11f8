"""`shockcal sensitivity`: Sobol indices of the emulated calibration features (SALib), over the prior box
and over the box of the joint posterior's 5-95% quantiles (shockcal.campaign.sensitivity says why a box).

Config keys: `sensitivity` (n_base, resamples), `inputs` (the prior box), study.seed (the
`sensitivity` stream), the shots' shear-modulus inputs (which summary rows are moduli, in GPa)."""

from __future__ import annotations

from shockcal.cli import add_command, add_config_argument

EXAMPLE_SENSITIVITY = """\
shockcal sensitivity --config config/config.yaml --emulator results/emulator \\
    --posterior-summary results/posterior/joint_summary.parquet --out results/sensitivity/sobol.csv"""


def register(subparsers) -> None:
    p = add_command(subparsers, "sensitivity", example=EXAMPLE_SENSITIVITY,
                    help="Sobol indices of the emulated features over the prior and posterior")
    add_config_argument(p)
    p.add_argument("--emulator", required=True, help="emulator directory (shockcal emulate --out)")
    p.add_argument("--posterior-summary", help="the joint posterior's summary (q05, q95 per input): adds the "
                                               "domain 'posterior_q05_q95'")
    p.add_argument("--out", required=True, help="table (CSV or Parquet): domain, shot, feature, input, S1, S1_conf, "
                                                "ST, ST_conf")
    p.add_argument("--n-base", type=int, help="override sensitivity.n_base (Saltelli base sample, a power of 2)")
    p.set_defaults(func=run)


def run(args) -> int:
    import logging
    import time
    from pathlib import Path

    import pandas as pd

    from shockcal.campaign.sensitivity import emulator_sobol, posterior_box
    from shockcal.emulator.study_emulator import Emulator
    from shockcal.io import atomic_path, read_table, write_table
    from shockcal.seeds import stream_seed
    from shockcal.study.config import input_columns, prior_bounds
    from shockcal.study.stages import load_stage_config

    config = load_stage_config(args.config, "sensitivity")
    settings = config["sensitivity"]
    n_base = args.n_base or settings["n_base"]
    seed = stream_seed(config["study"]["seed"], "sensitivity")
    emulator = Emulator.load(args.emulator)
    prior = prior_bounds(config)
    domains = {"prior": prior}
    if args.posterior_summary:
        names = [k for k in prior if k in emulator.required_inputs(emulator.shots)]
        domains["posterior_q05_q95"] = posterior_box(read_table(args.posterior_summary), names, input_columns(config))
    log = logging.getLogger("shockcal.campaign.sensitivity")
    parts = []
    for domain, bounds in domains.items():
        start = time.perf_counter()
        parts.append(emulator_sobol(emulator, emulator.shots, bounds, n_base, seed, settings["resamples"])
                     .assign(domain=domain))
        log.info("%s: Sobol indices of %d shots in %.1f s (n_base %d)", domain, len(emulator.shots),
                 time.perf_counter() - start, n_base)
    table = pd.concat(parts, ignore_index=True)
    table = table[["domain", *[c for c in table.columns if c != "domain"]]]
    if Path(args.out).suffix.lower() == ".csv":
        Path(args.out).parent.mkdir(parents=True, exist_ok=True)
        with atomic_path(args.out) as tmp:
            table.to_csv(tmp, index=False, float_format="%.6g")
    else:
        write_table(table, args.out, {"table": "Sobol indices", "n_base": n_base, "seed": seed,
                                      "resamples": settings["resamples"], "conf_level": 0.95})
    top = table.loc[table.groupby(["domain", "shot", "feature"], sort=False)["ST"].idxmax()]
    log.info("the input with the largest total index per feature:\n%s",
             top.to_string(index=False, float_format="%.3f"))
    return 0
