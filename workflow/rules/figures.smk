# The paper's fifteen figures and the study's own (Sobol indices), one rule per figure, each `shockcal figures --figure NAME`
# with its inputs passed as KEY=PATH pairs. PNG and PDF (figures.formats) under {RESULTS}/figures/;
# the PNG goes into the report with a caption from workflow/report/. The figures, their categories
# and the input keys each needs come from the catalogue (shockcal.study.figure_catalogue); this file only
# says which files make each kind of input.
from shockcal.study.figure_catalogue import INPUT_KINDS, catalogue, history_names

FIGURE_SPECS = catalogue(config)
HISTORY_SHOTS = history_names(config)
FIGURE_FORMATS = config["figures"]["formats"]
REPORT_FORMAT = "png" if "png" in FIGURE_FORMATS else FIGURE_FORMATS[0]


# input kind -> (shot or calibration name -> files)
INPUT_FILES = {
    "observed": lambda _: [rules.observed.output[0]],
    "cv": lambda _: [rules.emulator.output.cv],
    "emulator_predictions": lambda _: [rules.predict_emulator.output[0]],
    "record": lambda shot: [config["observed"]["records"][shot]["path"]],
    "sample_simulations": lambda shot: simulations(PLAN.training_run_set(shot), shot)[:1],
    "simulations": lambda shot: simulations(PLAN.training_run_set(shot), shot),
    "predicted_simulations": lambda shot: simulations("predict", shot),
    "features": lambda shot: expand(rules.features.output[0], run_set=PLAN.training_run_set(shot), shot=shot),
    "predicted_features": lambda shot: expand(rules.features.output[0], run_set="predict", shot=shot),
    "posterior": lambda name: [rules.calibrate.output.samples.format(name=name)],
    "sobol": lambda _: [rules.sensitivity.output[0]],
    "next_shot_ranking": lambda _: [rules.suggest_shot.output[0]],
}
assert set(INPUT_FILES) == set(INPUT_KINDS), "figures.smk: INPUT_FILES must cover the catalogue's INPUT_KINDS"
FIGURE_INPUTS = {
    name: {key: INPUT_FILES[key.partition(":")[0]](key.partition(":")[2]) for key in spec.needs}
    for name, spec in FIGURE_SPECS.items()
}


for _name, _spec in FIGURE_SPECS.items():
    _files = FIGURE_INPUTS[_name]

    rule:
        name:
            f"figure_{_name}"
        input:
            [path for paths in _files.values() for path in paths],
        output:
            report(
                f"{RESULTS}/figures/{_name}.{REPORT_FORMAT}",
                caption="../report/history.rst" if _name in HISTORY_SHOTS else f"../report/{_name}.rst",
                category=_spec.category,
            ),
            [f"{RESULTS}/figures/{_name}.{fmt}" for fmt in FIGURE_FORMATS if fmt != REPORT_FORMAT],
        log:
            f"{LOGS}/figures/{_name}.log",
        benchmark:
            f"{BENCHMARKS}/figures/{_name}.tsv"
        conda:
            "../envs/shockcal.yaml"
        params:
            figure=_name,
            shot=HISTORY_SHOTS.get(_name, ""),
            out_dir=lambda w, output: os.path.dirname(output[0]),
            inputs=" ".join(f"--input {key}={path}" for key, paths in _files.items() for path in paths),
            settings=figure_config(config, _name),
        shell:
            "shockcal figures --figure {params.figure} --out-dir {params.out_dir}" " {params.inputs} > {log} 2>&1"


# the figures of `all` (but those an archive study cannot make), and those of other targets (next_shot), by target
FIGURES_OF_ALL, TARGET_FIGURES = figure_targets(PLAN, FIGURE_SPECS, FIGURE_FORMATS)
ALL_TARGETS.extend(FIGURES_OF_ALL)
