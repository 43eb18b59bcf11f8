# Emulator: PC-GP on the design and every shot's features, with its leave-one-out table.


rule emulator:
    input:
        design=f"{RESULTS}/design.parquet",
        features=expand(f"{RESULTS}/features/{{shot}}.parquet", shot=SHOTS),
    output:
        emulator=f"{RESULTS}/emulator/emulator.json",
        arrays=f"{RESULTS}/emulator/emulator.npz",
        cv=f"{RESULTS}/emulator/cv.parquet",
        rmse=f"{RESULTS}/emulator/cv_rmse.csv",
    params:
        emulator=config["emulator"],
        seed=config["study"]["seed"],
        pairs=lambda w, input: " ".join(f"{s}={f}" for s, f in zip(SHOTS, input.features)),
        out=f"{RESULTS}/emulator",
    log:
        log_file("emulator"),
    benchmark:
        benchmark_file("emulator")
    threads: 2
    conda:
        "../envs/shockcal.yaml"
    shell:
        "shockcal emulate --config {EFFECTIVE_CONFIG} --design {input.design} --features {params.pairs}"
        " --out {params.out} > {log} 2>&1"


ALL_TARGETS.append(f"{RESULTS}/emulator/cv_rmse.csv")
