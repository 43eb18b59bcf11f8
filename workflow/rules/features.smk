# Features of every run set: per simulation chunk (they fan out with the simulations), merged per shot,
# where the failed-run budget is checked; observed features from the config or records.


rule features_chunk:
    input:
        rules.simulate.output[0],
    output:
        f"{RESULTS}/{{run_set}}/features/{{shot}}/chunk-{{chunk}}.parquet",
    log:
        f"{LOGS}/{{run_set}}/features/{{shot}}/chunk-{{chunk}}.log",
    benchmark:
        f"{BENCHMARKS}/{{run_set}}/features/{{shot}}/chunk-{{chunk}}.tsv"
    wildcard_constraints:
        run_set="|".join(PLAN.run_set_sizes),
    priority: 4  # after the hydrocode chunks that are ready, before figures and observed
    conda:
        "../envs/shockcal.yaml"
    params:
        settings=run_set_settings("features"),
        allow_empty=lambda w: PLAN.allow_empty(w.run_set),
    shell:
        "shockcal features --shot {wildcards.shot} --traces {input} --no-failure-budget {params.allow_empty}"
        " --out {output} > {log} 2>&1"


rule features:
    input:
        lambda w: expand(
            rules.features_chunk.output[0], run_set=w.run_set, shot=w.shot, chunk=PLAN.run_set_chunks[w.run_set]
        ),
    output:
        PLAN.features_path("{run_set}", "{shot}"),
    log:
        f"{LOGS}/{{run_set}}/features/{{shot}}.log",
    benchmark:
        f"{BENCHMARKS}/{{run_set}}/features/{{shot}}.tsv"
    wildcard_constraints:
        run_set="|".join(PLAN.run_set_sizes),
    conda:
        "../envs/shockcal.yaml"
    params:
        settings=run_set_settings("failure_budget"),
        allow_empty=lambda w: PLAN.allow_empty(w.run_set),
    shell:
        "shockcal features --shot {wildcards.shot} --tables {input} {params.allow_empty} --out {output} > {log} 2>&1"


rule observed:
    input:
        record_paths(config),
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


rule observed_base:
    """The base shots' observed features (the study without its new shots, PLAN.base_study), which a sequential
    study's steps and the new shots' design read: a shot added later leaves this file alone."""
    input:
        record_paths(PLAN.base_study),
    output:
        PLAN.observed_base_path,
    log:
        f"{LOGS}/observed_base.log",
    benchmark:
        f"{BENCHMARKS}/observed_base.tsv"
    conda:
        "../envs/shockcal.yaml"
    params:
        settings=stage_config(PLAN.base_study, "observed"),
        # the base study's config file, a channel as $SHOCKCAL_CONFIG is (the Snakefile): none without new shots.
        # A function of `input`, so snakemake does not track it: adding the first shot leaves this job alone.
        config=lambda w, input: PLAN.base_config_option,
    shell:
        "shockcal observed {params.config} --out {output} > {log} 2>&1"


ALL_TARGETS += [rules.features.output[0].format(run_set=PLAN.training_run_set(shot), shot=shot) for shot in SHOTS]
ALL_TARGETS += rules.observed.output
