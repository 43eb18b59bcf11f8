"""The study: the one room that reads the study config (config/config.yaml).

Layers, each importing only those above it and the library:
- `config`: accessors of a validated config (a shot's section, the inputs, the prior box, the end time);
- `adapters`: the config turned into the library's typed settings (`hydro_inputs`, `extractor_settings`,
  `emulator_spec`, `calibration_settings`, ...), the design and the measured features of the study;
- `validate`: reading a config file, its schema and the rules across keys, the design file's check;
- `stages`: which keys each stage reads (`STAGE_KEYS`), sliced for the workflow's params and the commands;
  `read_log`: with SHOCKCAL_READ_LOG, what each command read of its slice (the tests' check of `stages`);
- `strength_config`: the `strength` section: the law's prior box, checked before any run;
- `candidate_studies`: the next-shot check's candidates as fourth shots of derived configs;
- `figure_catalogue`: the figures, what each reads of the config and its inputs, and which function draws it;
- `workflow`, `stage_times`: the Snakefile's helpers and the per-stage cost table from its benchmark files;
- `snakemake_console`: snakemake's console at one progress line (`snakemake --logger shockcal`, what `make` runs).

The library (hydro, simulators, design, velocimetry, emulator, inference, campaign) never imports this package: the
`shockcal` commands call an adapter, and the adapter hands the library typed settings.
"""
