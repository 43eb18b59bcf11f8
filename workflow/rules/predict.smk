# Posterior predictions: predict.n_posterior_runs seeded joint-posterior draws, run through the
# hydrocode as the run set "predict" (simulate.smk, features.smk; Figs 10-13), and the emulator's
# predictions at the same draws (Fig 9).


rule predict_design:
    input:
        posterior=expand(rules.calibrate.output.samples, name="joint"),
    output:
        PLAN.run_set_path("predict", "design.parquet"),
    log:
        f"{LOGS}/predict/design.log",
    benchmark:
        f"{BENCHMARKS}/predict/design.tsv"
    conda:
        "../envs/shockcal.yaml"
    params:
        settings=stage_config(config, "predict"),
    shell:
        "shockcal predict --posterior {input.posterior} --out {output} > {log} 2>&1"


rule predict_emulator:
    input:
        design=rules.predict_design.output[0],
        emulator=rules.emulator.output.emulator,
        arrays=rules.emulator.output.arrays,
    output:
        PLAN.run_set_path("predict", "emulator.parquet"),
    log:
        f"{LOGS}/predict/emulator.log",
    benchmark:
        f"{BENCHMARKS}/predict/emulator.tsv"
    conda:
        "../envs/shockcal.yaml"
    threads: config["emulator"]["n_jobs"]  # the emulator predicts on its n_jobs threads
    params:
        settings=stage_config(config, "emulate_predict"),
        emulator_dir=lambda w, input: os.path.dirname(input.emulator),
    shell:
        "shockcal predict-emulator --design {input.design}"
        " --emulator {params.emulator_dir} --out {output} > {log} 2>&1"


rule posterior_netcdf:
    """A calibration's posterior as ArviZ InferenceData (docs/calibration.md, "Outputs"); the joint one with the
    features of the hydrocode runs at its draws as posterior_predictive."""
    input:
        samples=rules.calibrate.output.samples,
        weighted=rules.calibrate.output.weighted,
        predicted=lambda w: (
            expand(rules.features.output[0], run_set="predict", shot=SHOTS)
            if w.name == "joint" and not PLAN.archive
            else []
        ),
    output:
        f"{RESULTS}/posterior/{{name}}.nc",
    log:
        f"{LOGS}/posterior_netcdf/{{name}}.log",
    benchmark:
        f"{BENCHMARKS}/posterior_netcdf/{{name}}.tsv"
    wildcard_constraints:
        name="|".join(CALIBRATIONS),
    conda:
        "../envs/shockcal.yaml"
    params:
        settings=stage_config(config, "calibrate"),  # the prior box; its digest is the file's config_digest
        predicted=lambda w, input: f"--predicted-features {pairs(SHOTS, input.predicted)}" if input.predicted else "",
    shell:
        "shockcal posterior-netcdf --posterior {input.samples} {params.predicted} --out {output} > {log} 2>&1"


ALL_TARGETS += expand(rules.posterior_netcdf.output[0], name=CALIBRATIONS)
