# Features: per shot from all its simulation chunks; observed features from the config or records.


rule features:
    input:
        expand(f"{RESULTS}/simulations/{{{{shot}}}}/chunk-{{chunk}}.parquet", chunk=CHUNKS),
    output:
        f"{RESULTS}/features/{{shot}}.parquet",
    log:
        f"{LOGS}/features/{{shot}}.log",
    benchmark:
        f"{BENCHMARKS}/features/{{shot}}.tsv"
    conda:
        "../envs/shockcal.yaml"
    params:
        features=config["features"],
        analysis=lambda w: config["shots"][w.shot].get("analysis", {}),
        max_failed_fraction=config["simulate"]["max_failed_fraction"],
    shell:
        "shockcal features --shot {wildcards.shot} --traces {input} --out {output} > {log} 2>&1"


rule observed:
    input:
        [spec["path"] for spec in config["observed"]["records"].values()]
        if config["observed"]["source"] == "records"
        else [],
    output:
        f"{RESULTS}/features/observed.parquet",
    log:
        f"{LOGS}/observed.log",
    benchmark:
        f"{BENCHMARKS}/observed.tsv"
    conda:
        "../envs/shockcal.yaml"
    params:
        observed=config["observed"],
        features=config["features"],
        analysis={shot: spec.get("analysis", {}) for shot, spec in config["shots"].items()},
    shell:
        "shockcal observed --out {output} > {log} 2>&1"


ALL_TARGETS += expand(f"{RESULTS}/features/{{shot}}.parquet", shot=SHOTS)
ALL_TARGETS.append(f"{RESULTS}/features/observed.parquet")
