# Hydrocode run sets beyond the training design, run exactly like the training runs (`shockcal
# simulate`, chunked, then `shockcal features`):
#   predict: predict.n_posterior_runs seeded joint-posterior draws (Figs 10-13), and the emulator's
#            predictions at the same draws (Fig 9);
#   check:   calibration.check.trials truths on a Latin hypercube over the box, for the synthetic-truth
#            check with hydrocode-made pseudo-measurements (calibrate.smk).
PREDICT = f"{RESULTS}/predict"
RUN_SETS = {"predict": config["predict"]["n_posterior_runs"], "check": config["calibration"]["check"]["trials"]}


def run_set_chunks(name):
    return list(range(-(-RUN_SETS[name] // CHUNK_SIZE)))


PREDICT_CHUNKS = run_set_chunks("predict")


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


rule check_design:
    output:
        f"{RESULTS}/check/design.parquet",
    params:
        trials=RUN_SETS["check"],
        inputs=config["inputs"],
        seed=config["study"]["seed"] + config["calibration"]["seed_offset"] + 2,
    log:
        log_file("check/design"),
    benchmark:
        benchmark_file("check/design")
    conda:
        "../envs/shockcal.yaml"
    shell:
        "shockcal design --config {EFFECTIVE_CONFIG} --lhs --n-runs {params.trials} --seed {params.seed}"
        " --out {output} > {log} 2>&1"


rule run_set_simulate:
    input:
        design=f"{RESULTS}/{{run_set}}/design.parquet",
    output:
        f"{RESULTS}/{{run_set}}/simulations/{{shot}}/chunk-{{chunk}}.parquet",
    wildcard_constraints:
        run_set="|".join(RUN_SETS),
    params:
        physics=lambda w: physics_slice(w.shot),
        rows=chunk_rows,
    log:
        log_file("{run_set}/simulate/{shot}/chunk-{chunk}"),
    benchmark:
        benchmark_file("{run_set}/simulate/{shot}/chunk-{chunk}")
    conda:
        "../envs/shockcal.yaml"
    shell:
        "shockcal simulate --config {EFFECTIVE_CONFIG} --shot {wildcards.shot} --design {input.design}"
        " --rows {params.rows} --out {output} > {log} 2>&1"


rule run_set_features:
    input:
        lambda w: expand(
            f"{RESULTS}/{w.run_set}/simulations/{w.shot}/chunk-{{chunk}}.parquet", chunk=run_set_chunks(w.run_set)
        ),
    output:
        f"{RESULTS}/{{run_set}}/features/{{shot}}.parquet",
    wildcard_constraints:
        run_set="|".join(RUN_SETS),
    params:
        features=config["features"],
        analysis=lambda w: config["shots"][w.shot].get("analysis", {}),
        max_failed_fraction=config["simulate"]["max_failed_fraction"],
    log:
        log_file("{run_set}/features/{shot}"),
    benchmark:
        benchmark_file("{run_set}/features/{shot}")
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
