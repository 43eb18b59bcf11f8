# Design: the seeded Latin hypercube over the prior box, or the config's design file.


rule design:
    output:
        f"{RESULTS}/design.parquet",
    log:
        f"{LOGS}/design.log",
    benchmark:
        f"{BENCHMARKS}/design.tsv"
    conda:
        "../envs/shockcal.yaml"
    params:
        settings=stage_config(config, "design"),
    shell:
        "shockcal design --out {output} > {log} 2>&1"
