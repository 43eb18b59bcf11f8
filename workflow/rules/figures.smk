# The paper's fifteen figures (issue 7), one rule per figure, each `shockcal figures --figure NAME`
# with its inputs passed as KEY=PATH pairs (keys: see shockcal.plots.catalogue). PNG and PDF
# (figures.formats) under {RESULTS}/figures/; the PNG goes into the report with a caption from
# workflow/report/. Figure names and categories come from the catalogue, the files from here.
from shockcal.plots.catalogue import catalogue, history_names

FIGURE_SPECS = catalogue(config)
HISTORY_SHOTS = history_names(config)
FIGURE_FORMATS = config["figures"]["formats"]
REPORT_FORMAT = "png" if "png" in FIGURE_FORMATS else FIGURE_FORMATS[0]
RECORD_FILES = {shot: [spec["path"]] for shot, spec in config["observed"]["records"].items()}
OBSERVED_FEATURES = rules.observed.output[0]
SIMULATION_CHUNKS = {shot: expand(rules.simulate.output[0], shot=shot, chunk=CHUNKS) for shot in SHOTS}
PREDICTED_SIMULATION_CHUNKS = {
    shot: expand(rules.run_set_simulate.output[0], run_set="predict", shot=shot, chunk=PREDICT_CHUNKS) for shot in SHOTS
}
TRAINING_FEATURES = {f"features:{shot}": expand(rules.features.output[0], shot=shot) for shot in SHOTS}
PREDICTED_FEATURES = {
    f"predicted_features:{shot}": expand(rules.run_set_features.output[0], run_set="predict", shot=shot)
    for shot in SHOTS
}
POSTERIOR = {f"posterior:{name}": expand(rules.calibrate.output.samples, name=name) for name in CALIBRATIONS}
# Figs 4, 5, 15 draw one trace: the first shot's record when configured, else its first simulation chunk.
TRACE_INPUTS = (
    {f"record:{SHOTS[0]}": RECORD_FILES[SHOTS[0]]}
    if SHOTS[0] in RECORD_FILES
    else {f"simulations:{SHOTS[0]}": SIMULATION_CHUNKS[SHOTS[0]][:1]}
)
FIGURE_INPUTS = {
    "fig02_records": {"observed": [OBSERVED_FEATURES], **{f"record:{s}": p for s, p in RECORD_FILES.items()}},
    "fig04_trace_features": TRACE_INPUTS,
    "fig05_mixture_split": TRACE_INPUTS,
    "fig06_crossval": {"cv": [rules.emulator.output.cv]},
    "fig07_marginals": POSTERIOR,
    "fig08_pairs": {"posterior:joint": POSTERIOR["posterior:joint"]},
    "fig09_features_emulator": {
        **TRAINING_FEATURES,
        "observed": [OBSERVED_FEATURES],
        "emulator_predictions": rules.predict_emulator.output,
    },
    "fig10_features_hydrocode": {
        **TRAINING_FEATURES,
        "observed": [OBSERVED_FEATURES],
        **PREDICTED_FEATURES,
    },
    "fig15_pit_construction": TRACE_INPUTS,
    **{
        name: {
            "observed": [OBSERVED_FEATURES],
            f"simulations:{shot}": SIMULATION_CHUNKS[shot],
            f"predicted_simulations:{shot}": PREDICTED_SIMULATION_CHUNKS[shot],
            f"features:{shot}": TRAINING_FEATURES[f"features:{shot}"],
            f"predicted_features:{shot}": PREDICTED_FEATURES[f"predicted_features:{shot}"],
            **({f"record:{shot}": RECORD_FILES[shot]} if shot in RECORD_FILES else {}),
        }
        for name, shot in HISTORY_SHOTS.items()
    },
}


for _name, _spec in FIGURE_SPECS.items():
    _files = FIGURE_INPUTS.get(_name, {})

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


ALL_TARGETS.extend(f"{RESULTS}/figures/{name}.{fmt}" for name in FIGURE_SPECS for fmt in FIGURE_FORMATS)
