# Simulate: one job per shot and chunk of design rows. The design is an `ancient` input: a chunk
# reruns when its own rows (params.rows_digest) or the physics change, not when the design file is
# rewritten with the same rows.


rule simulate:
    input:
        design=ancient(f"{RESULTS}/design.parquet"),
    output:
        f"{RESULTS}/simulations/{{shot}}/chunk-{{chunk}}.parquet",
    params:
        physics=lambda w: physics_slice(w.shot),
        rows=chunk_rows,
        rows_digest=lambda w: CHUNK_DIGESTS[int(w.chunk)],
    log:
        log_file("simulate/{shot}/chunk-{chunk}"),
    benchmark:
        benchmark_file("simulate/{shot}/chunk-{chunk}")
    conda:
        "../envs/shockcal.yaml"
    shell:
        "shockcal simulate --config {EFFECTIVE_CONFIG} --shot {wildcards.shot} --design {input.design}"
        " --rows {params.rows} --out {output} > {log} 2>&1"
