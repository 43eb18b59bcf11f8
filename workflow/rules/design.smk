# Design: the seeded Latin hypercube over the prior box, or the config's design file.


rule design:
    output:
        f"{RESULTS}/design.parquet",
    params:
        design=config["design"],
        inputs=config["inputs"],
        seed=config["study"]["seed"],
    log:
        log_file("design"),
    benchmark:
        benchmark_file("design")
    conda:
        "../envs/shockcal.yaml"
    shell:
        "shockcal design --config {EFFECTIVE_CONFIG} --out {output} > {log} 2>&1"
