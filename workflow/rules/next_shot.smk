# Which shot next (docs/next_shot.md): each next-shot candidate's design (next_shot.n_draws
# joint-posterior draws at its conditions), run as the run set "next_shot" through simulate.smk and
# features.smk (the candidate's name in the shot's place, chunks of simulate.chunk_size runs), and the
# ranking of the candidates by expected information gain. Outside `all`: `make next-shot`
# (snakemake next_shot), which also draws the figure (figures.smk).


rule next_shot_design:
    """A candidate's design; a candidate whose impact drives no plastic wave stops here, before any run
    (the designs go first: priority)."""
    input:
        posterior=expand(rules.calibrate.output.samples, name="joint"),
    output:
        PLAN.run_set_path("next_shot", "designs", "{shot}.parquet"),
    log:
        f"{LOGS}/next_shot/design/{{shot}}.log",
    benchmark:
        f"{BENCHMARKS}/next_shot/design/{{shot}}.tsv"
    wildcard_constraints:
        shot="|".join(re.escape(name) for name in CANDIDATES),
    priority: 50
    conda:
        "../envs/shockcal.yaml"
    params:
        settings=lambda w: stage_config(config, "next_shot_design", w.shot),
    shell:
        "shockcal next-shot-design --candidate {wildcards.shot} --posterior {input.posterior}"
        " --out {output} > {log} 2>&1"


rule suggest_shot:
    input:
        designs=expand(rules.next_shot_design.output[0], shot=CANDIDATES),
        features=expand(rules.features.output[0], run_set="next_shot", shot=CANDIDATES),
        rmse=rules.emulator.output.rmse if config["next_shot"]["emulator_error"] else [],
        observed=rules.observed.output[0],
    output:
        f"{RESULTS}/next_shot/ranking.csv",
    log:
        f"{LOGS}/next_shot/suggest_shot.log",
    benchmark:
        f"{BENCHMARKS}/next_shot/suggest_shot.tsv"
    conda:
        "../envs/shockcal.yaml"
    params:
        settings=stage_config(config, "suggest_shot"),
        designs=lambda w, input: pairs(CANDIDATES, input.designs),
        features=lambda w, input: pairs(CANDIDATES, input.features),
        rmse=lambda w, input: f"--emulator-rmse {input.rmse}" if input.rmse else "",
    shell:
        "shockcal suggest-shot --designs {params.designs} --features {params.features} {params.rmse}"
        " --observed {input.observed} --out {output} > {log} 2>&1"
