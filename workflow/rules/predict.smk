# Posterior predictive runs (issue 7): draw predict.n_posterior_runs joint-posterior samples (seeded)
# into a design table, run them through the hydrocode exactly like the training runs (`shockcal
# simulate`, chunked), extract their features (`shockcal features`), and predict the features at the
# same draws with the emulator. Figures 9-13 read these products under {RESULTS}/predict/.

PREDICT = f"{RESULTS}/predict"
PREDICT_CHUNKS = list(range(-(-config["predict"]["n_posterior_runs"] // CHUNK_SIZE)))


rule predict_design:
    input:
        posterior=f"{RESULTS}/posterior/joint.parquet",
    output:
        f"{PREDICT}/design.parquet",
    params:
        predict=config["predict"],
        seed=config["study"]["seed"],
    log:
        log_file("predict/design"),
    benchmark:
        benchmark_file("predict/design")
    conda:
        "../envs/shockcal.yaml"
    shell:
        "shockcal predict --config {EFFECTIVE_CONFIG} --posterior {input.posterior} --out {output} > {log} 2>&1"


rule predict_simulate:
    input:
        design=f"{PREDICT}/design.parquet",
    output:
        f"{PREDICT}/simulations/{{shot}}/chunk-{{chunk}}.parquet",
    params:
        physics=lambda w: physics_slice(w.shot),
        rows=chunk_rows,
    log:
        log_file("predict/simulate/{shot}/chunk-{chunk}"),
    benchmark:
        benchmark_file("predict/simulate/{shot}/chunk-{chunk}")
    conda:
        "../envs/shockcal.yaml"
    shell:
        "shockcal simulate --config {EFFECTIVE_CONFIG} --shot {wildcards.shot} --design {input.design}"
        " --rows {params.rows} --out {output} > {log} 2>&1"


rule predict_features:
    input:
        expand(f"{PREDICT}/simulations/{{{{shot}}}}/chunk-{{chunk}}.parquet", chunk=PREDICT_CHUNKS),
    output:
        f"{PREDICT}/features/{{shot}}.parquet",
    params:
        features=config["features"],
        analysis=lambda w: config["shots"][w.shot].get("analysis", {}),
        max_failed_fraction=config["simulate"]["max_failed_fraction"],
    log:
        log_file("predict/features/{shot}"),
    benchmark:
        benchmark_file("predict/features/{shot}")
    conda:
        "../envs/shockcal.yaml"
    shell:
        "shockcal features --config {EFFECTIVE_CONFIG} --shot {wildcards.shot} --traces {input} --out {output}"
        " > {log} 2>&1"


rule predict_emulator:
    input:
        design=f"{PREDICT}/design.parquet",
        emulator=f"{RESULTS}/emulator/emulator.json",
        arrays=f"{RESULTS}/emulator/emulator.npz",
    output:
        f"{PREDICT}/emulator.parquet",
    params:
        emulator_dir=f"{RESULTS}/emulator",
    log:
        log_file("predict/emulator"),
    benchmark:
        benchmark_file("predict/emulator")
    conda:
        "../envs/shockcal.yaml"
    shell:
        "shockcal predict-emulator --config {EFFECTIVE_CONFIG} --design {input.design}"
        " --emulator {params.emulator_dir} --out {output} > {log} 2>&1"
