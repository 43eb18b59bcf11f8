# Hydrocode run sets beyond the training design, run exactly like the training runs (`shockcal
# simulate`, chunked, then `shockcal features`):
#   predict: predict.n_posterior_runs seeded joint-posterior draws (Figs 10-13), and the emulator's
#            predictions at the same draws (Fig 9);
#   check:   calibration.check.trials truths on a Latin hypercube over the box, for the synthetic-truth
#            check with hydrocode-made pseudo-measurements (calibrate.smk).
PREDICT = f"{RESULTS}/predict"
RUN_SETS = {"predict": config["predict"]["n_posterior_runs"], "check": config["calibration"]["check"]["trials"]}
RUN_SET_CHUNKS = {name: list(range(chunk_count(n, CHUNK_SIZE))) for name, n in RUN_SETS.items()}
PREDICT_CHUNKS = RUN_SET_CHUNKS["predict"]


rule predict_design:
    input:
        posterior=expand(rules.calibrate.output.samples, name="joint"),
    output:
        f"{PREDICT}/design.parquet",
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


rule check_design:
    output:
        f"{RESULTS}/check/design.parquet",
    log:
        f"{LOGS}/check/design.log",
    benchmark:
        f"{BENCHMARKS}/check/design.tsv"
    conda:
        "../envs/shockcal.yaml"
    params:
        settings=stage_config(config, "check_design"),
    shell:
        "shockcal design --stream check_design --out {output} > {log} 2>&1"


rule run_set_simulate:
    input:
        design=f"{RESULTS}/{{run_set}}/design.parquet",
    output:
        f"{RESULTS}/{{run_set}}/simulations/{{shot}}/chunk-{{chunk}}.parquet",
    log:
        f"{LOGS}/{{run_set}}/simulate/{{shot}}/chunk-{{chunk}}.log",
    benchmark:
        f"{BENCHMARKS}/{{run_set}}/simulate/{{shot}}/chunk-{{chunk}}.tsv"
    wildcard_constraints:
        run_set="|".join(RUN_SETS),
    conda:
        "../envs/shockcal.yaml"
    params:
        settings=lambda w: stage_config(config, "simulate", w.shot),
        rows=lambda w: chunk_rows(w.chunk, CHUNK_SIZE),
        end_time=lambda w: f"--end-time-us {config['predict']['end_time_us']}" if w.run_set == "predict" else "",
    shell:
        "shockcal simulate --shot {wildcards.shot} --design {input.design}"
        " --rows {params.rows} {params.end_time} --out {output} > {log} 2>&1"


rule run_set_features:
    input:
        lambda w: expand(
            rules.run_set_simulate.output[0], run_set=w.run_set, shot=w.shot, chunk=RUN_SET_CHUNKS[w.run_set]
        ),
    output:
        f"{RESULTS}/{{run_set}}/features/{{shot}}.parquet",
    log:
        f"{LOGS}/{{run_set}}/features/{{shot}}.log",
    benchmark:
        f"{BENCHMARKS}/{{run_set}}/features/{{shot}}.tsv"
    wildcard_constraints:
        run_set="|".join(RUN_SETS),
    conda:
        "../envs/shockcal.yaml"
    params:
        settings=lambda w: stage_config(config, ["features", "failure_budget"], w.shot),
    shell:
        "shockcal features --shot {wildcards.shot} --traces {input} --out {output}" " > {log} 2>&1"


rule predict_emulator:
    input:
        design=rules.predict_design.output[0],
        emulator=rules.emulator.output.emulator,
        arrays=rules.emulator.output.arrays,
    output:
        f"{PREDICT}/emulator.parquet",
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
