# Emulator: PC-GP on the design and every shot's features, with its cross-validation: closed-form LOO
# (cv.parquet, the fast diagnostic), K-fold and the outer check (cv_heldout.parquet), all in cv_rmse.csv
# with a `scheme` column.


rule emulator:
    input:
        design=STUDY_RUNS["design"],  # the training runs; a sequential study's every wave (waves.smk)
        features=STUDY_RUNS["features"],
    output:
        emulator=f"{RESULTS}/emulator/emulator.json",
        arrays=f"{RESULTS}/emulator/emulator.npz",
        cv=f"{RESULTS}/emulator/cv.parquet",
        heldout=f"{RESULTS}/emulator/cv_heldout.parquet",
        rmse=f"{RESULTS}/emulator/cv_rmse.csv",
    log:
        f"{LOGS}/emulator.log",
    benchmark:
        f"{BENCHMARKS}/emulator.tsv"
    conda:
        "../envs/shockcal.yaml"
    threads: config["emulator"]["n_jobs"]
    params:
        settings=stage_config(config, "emulate"),
        pairs=lambda w, input: " ".join(f"{s}={f}" for s, f in zip(SHOTS, input.features)),
        out=lambda w, output: os.path.dirname(output.emulator),
    shell:
        "shockcal emulate --design {input.design} --features {params.pairs}" " --out {params.out} > {log} 2>&1"


ALL_TARGETS.append(rules.emulator.output.rmse)
