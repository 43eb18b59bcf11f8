# Simulate: one job per shot and chunk of design rows. The design is an `ancient` input: a chunk
# reruns when its own rows (params.rows_digest: their run ids and the columns this shot reads) or the
# physics change, not when the design file is rewritten with the same rows or gains another shot's column.


rule simulate:
    input:
        design=ancient(DESIGN),
    output:
        f"{RESULTS}/simulations/{{shot}}/chunk-{{chunk}}.parquet",
    log:
        f"{LOGS}/simulate/{{shot}}/chunk-{{chunk}}.log",
    benchmark:
        f"{BENCHMARKS}/simulate/{{shot}}/chunk-{{chunk}}.tsv"
    conda:
        "../envs/shockcal.yaml"
    params:
        settings=lambda w: stage_config(config, "simulate", w.shot),
        rows=lambda w: chunk_rows(w.chunk, CHUNK_SIZE),
        rows_digest=lambda w: CHUNK_DIGESTS[w.shot][int(w.chunk)],
    shell:
        "shockcal simulate --shot {wildcards.shot} --design {input.design}"
        " --rows {params.rows} --out {output} > {log} 2>&1"
