# Simulate: every run set (training, predict, check) the same way, one job per run set, shot and chunk
# of design rows, under {RESULTS}/{run_set}/simulations/. The training design is made when the workflow
# is read (design.smk) and is an `ancient` input: a training chunk reruns when its own rows
# (params.rows_digest: their run ids and the columns this shot reads) or the physics change, not when
# the design file is rewritten with the same rows or gains another shot's column. The predict and check
# designs are made by jobs (predict.smk, calibrate.smk), and their chunks follow them.


rule simulate:
    input:
        design=run_set_design,
    output:
        f"{RESULTS}/{{run_set}}/simulations/{{shot}}/chunk-{{chunk}}.parquet",
    log:
        f"{LOGS}/{{run_set}}/simulate/{{shot}}/chunk-{{chunk}}.log",
    benchmark:
        f"{BENCHMARKS}/{{run_set}}/simulate/{{shot}}/chunk-{{chunk}}.tsv"
    wildcard_constraints:
        run_set="|".join(RUN_SET_SIZES),
    priority: simulate_priority  # longest chunk first, before figures and observed (common.smk)
    conda:
        "../envs/shockcal.yaml"
    params:
        settings=run_set_settings("simulate"),
        rows=lambda w: chunk_rows(
            w.chunk,
            RUN_SET_CHUNK_SIZE[w.run_set],
            RUN_SET_SIZES[w.run_set] if w.run_set == "next_shot_check" else None,
        ),
        rows_digest=lambda w: (
            CHUNK_DIGESTS[w.shot][int(w.chunk)]
            if w.run_set == "training"
            else CHECK_DIGESTS[w.shot][int(w.chunk)] if w.run_set == "next_shot_check" else ""
        ),
        end_time=lambda w: f"--end-time-us {config['predict']['end_time_us']}" if w.run_set == "predict" else "",
        allow_empty=allow_empty,
    shell:
        "shockcal simulate --shot {wildcards.shot} --design {input.design}"
        " --rows {params.rows} {params.end_time} {params.allow_empty} --out {output} > {log} 2>&1"
