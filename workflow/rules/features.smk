# Features: per simulation chunk (they fan out with the simulations), merged per shot, where the
# failed-run budget is checked; observed features from the config or records.


rule features_chunk:
    input:
        rules.simulate.output[0],
    output:
        f"{RESULTS}/features/{{shot}}/chunk-{{chunk}}.parquet",
    log:
        f"{LOGS}/features/{{shot}}/chunk-{{chunk}}.log",
    benchmark:
        f"{BENCHMARKS}/features/{{shot}}/chunk-{{chunk}}.tsv"
    conda:
        "../envs/shockcal.yaml"
    params:
        settings=lambda w: stage_config(config, "features", w.shot),
    shell:
        "shockcal features --shot {wildcards.shot} --traces {input} --no-failure-budget --out {output} > {log} 2>&1"


rule features:
    input:
        expand(rules.features_chunk.output[0], chunk=CHUNKS, allow_missing=True),
    output:
        f"{RESULTS}/features/{{shot}}.parquet",
    log:
        f"{LOGS}/features/{{shot}}.log",
    benchmark:
        f"{BENCHMARKS}/features/{{shot}}.tsv"
    conda:
        "../envs/shockcal.yaml"
    params:
        settings=lambda w: stage_config(config, "failure_budget", w.shot),
    shell:
        "shockcal features --shot {wildcards.shot} --tables {input} --out {output} > {log} 2>&1"


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
        settings=stage_config(config, "observed"),
    shell:
        "shockcal observed --out {output} > {log} 2>&1"


ALL_TARGETS += expand(rules.features.output[0], shot=SHOTS)
ALL_TARGETS += rules.observed.output
