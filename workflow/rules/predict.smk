# Posterior predictions: predict.n_posterior_runs seeded joint-posterior draws, run through the
# hydrocode as the run set "predict" (simulate.smk, features.smk; Figs 10-13), and the emulator's
# predictions at the same draws (Fig 9).


rule predict_design:
    input:
        posterior=expand(rules.calibrate.output.samples, name="joint"),
    output:
        run_set_path("predict", "design.parquet"),
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
        run_set_path("predict", "emulator.parquet"),
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
