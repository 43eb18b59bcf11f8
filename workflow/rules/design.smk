# Design: the seeded Latin hypercube over the prior box, or the config's design file.


rule design:
    output:
        f"{RESULTS}/design.parquet",
    params:
        design=config["design"],
        inputs=config["inputs"],
        seed=config["study"]["seed"],
    log:
        f"{LOGS}/design.log",
    benchmark:
        f"{BENCHMARKS}/design.tsv"
    conda:
        "../envs/shockcal.yaml"
    shell:
        "shockcal design --out {output} > {log} 2>&1"
