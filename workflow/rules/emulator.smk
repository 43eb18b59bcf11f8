# Emulator: PC-GP on the design and every shot's features, with its cross-validation: closed-form LOO
# (cv.parquet, the fast diagnostic), K-fold and the outer check (cv_heldout.parquet), all in cv_rmse.csv
# with a `scheme` column.


rule emulator:
    input:
        # the training runs (a sequential study's every wave, waves.smk); each new shot's own runs and design
        **PLAN.study_runs(),
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
        # the features' SHOT=FILE pairs, then each new shot's own design (--shot-design): one param, so the
        # command of a study without new shots is the one it ran with (a changed command reruns the emulator)
        pairs=lambda w, input: " ".join(
            [
                pairs(SHOTS, input.features),
                *(["--shot-design", pairs(PLAN.new_shots, input.shot_designs)] if PLAN.new_shots else []),
            ]
        ),
        out=lambda w, output: os.path.dirname(output.emulator),
    shell:
        "shockcal emulate --design {input.design} --features {params.pairs}" " --out {params.out} > {log} 2>&1"


ALL_TARGETS.append(rules.emulator.output.rmse)
