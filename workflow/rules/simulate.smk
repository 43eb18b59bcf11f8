# Run sets: every set of hydrocode runs goes through the same rules (simulate.smk, features.smk) and the same
# paths, {RESULTS}/{run_set}/{design.parquet, simulations/, features/}, in chunks of design rows (their sizes,
# chunks and order: the plan, src/shockcal/study/workflow_plan.py):
#   training: the training design (the seeded Latin hypercube over the prior box, or the config's design file),
#             written when the workflow is read (the Snakefile), for the emulator;
#   predict:  predict.n_posterior_runs seeded joint-posterior draws (Figs 10-13; predict.smk);
#   verify:   verify.n_draws seeded joint-posterior draws, the hydrocode's verdict (`make verify`; verify.smk);
#   check, check_posterior: calibration.check.trials truths for the synthetic-truth checks (calibrate.smk);
#   next_shot: next_shot.n_draws joint-posterior draws at each next-shot candidate, whose names take the
#             shots' place (next_shot.smk);
#   wave1, wave2, ...: a sequential study's later waves (waves.smk), the training run set is then wave 0;
#   next_shot_check, next_shot_truth: the realized check's candidates' training runs and truths
#             (next_shot_check.smk); new_shot: each new shot's own runs (design.new_shots; waves.smk).
# The training design and a check candidate's are `ancient` inputs: a training chunk reruns when its own rows
# (params.rows_digest: their run ids and the columns this shot reads) or the physics change, not when the design
# file is rewritten with the same rows or gains another shot's column. The other designs are made by jobs.


rule simulate:
    input:
        design=lambda w: PLAN.design_input(w.run_set, w.shot),
    output:
        f"{RESULTS}/{{run_set}}/simulations/{{shot}}/chunk-{{chunk}}.parquet",
    log:
        f"{LOGS}/{{run_set}}/simulate/{{shot}}/chunk-{{chunk}}.log",
    benchmark:
        f"{BENCHMARKS}/{{run_set}}/simulate/{{shot}}/chunk-{{chunk}}.tsv"
    wildcard_constraints:
        run_set="|".join(PLAN.run_set_sizes),
    # longest chunk first, before figures and observed (docs/workflow.md, "Job order")
    priority: lambda w: PLAN.simulate_priority(w.run_set, w.shot, w.chunk)
    conda:
        "../envs/shockcal.yaml"
    params:
        settings=run_set_settings("simulate"),
        rows=lambda w: PLAN.chunk_rows(w.run_set, w.chunk),
        rows_digest=lambda w: PLAN.rows_digest(w.run_set, w.shot, w.chunk),
        end_time=lambda w: f"--end-time-us {config['predict']['end_time_us']}" if w.run_set == "predict" else "",
        allow_empty=lambda w: PLAN.allow_empty(w.run_set),
    shell:
        "shockcal simulate --shot {wildcards.shot} --design {input.design}"
        " --rows {params.rows} {params.end_time} {params.allow_empty} --out {output} > {log} 2>&1"
