# The realized check of the next-shot ranking (docs/next_shot.md, "The realized check"): each compared
# candidate (PLAN.check_plans, planned when the workflow is read) as the fourth shot of a derived study, its training runs (run set
# next_shot_check) and the truths' runs at every shot (run set next_shot_truth) through simulate.smk and
# features.smk; an emulator on the first next_shot.check.n_training_runs rows of the three shots (baseline) and of
# the four (each candidate); each truth calibrated by `shockcal calibrate-check` with every one; the summary.
# Outside `all`: `make next-shot-check` (snakemake next_shot_check).

CHECK_SECTION = config["next_shot"]["check"]
CHECK_MODELS = PLAN.check_models()


rule next_shot_check_truths:
    """The check's truths: next_shot.check.n_truths joint-posterior draws, with each candidate's inputs."""
    input:
        posterior=expand(rules.calibrate.output.samples, name="joint"),
    output:
        truths=PLAN.run_set_path("next_shot_truth", "design.parquet"),
        designs=expand(PLAN.run_set_path("next_shot_truth", "designs", "{shot}.parquet"), shot=list(PLAN.check_plans)),
    log:
        f"{LOGS}/next_shot_truth/design.log",
    benchmark:
        f"{BENCHMARKS}/next_shot_truth/design.tsv"
    conda:
        "../envs/shockcal.yaml"
    params:
        settings=stage_config(config, "next_shot_check_truths"),
        candidates=" ".join(PLAN.check_plans),
        designs=lambda w, output: pairs(PLAN.check_plans, output.designs),
    shell:
        "shockcal next-shot-check-truths --posterior {input.posterior} --candidates {params.candidates}"
        " --out {output.truths} --candidate-designs {params.designs} > {log} 2>&1"


rule next_shot_check_emulator:
    """The check's emulator of a model (baseline: the three shots; a candidate: the four), on the first
    next_shot.check.n_training_runs rows, with the study's emulator settings."""
    input:
        unpack(lambda w: PLAN.check_emulator_inputs(w.model)),
    output:
        emulator=f"{RESULTS}/next_shot/check/{{model}}/emulator/emulator.json",
    log:
        f"{LOGS}/next_shot/check/{{model}}/emulator.log",
    benchmark:
        f"{BENCHMARKS}/next_shot/check/{{model}}/emulator.tsv"
    wildcard_constraints:
        model="|".join(re.escape(name) for name in CHECK_MODELS),
    conda:
        "../envs/shockcal.yaml"
    threads: config["emulator"]["n_jobs"]
    params:
        settings=lambda w: stage_config(PLAN.check_model_study(w.model), "emulate"),
        config=lambda w: PLAN.check_model_config_option(w.model),
        pairs=lambda w, input: pairs(PLAN.check_model_shots(w.model), input.features),
        runs=CHECK_SECTION["n_training_runs"],
        out=lambda w, output: os.path.dirname(output.emulator),
    shell:
        "shockcal emulate {params.config} --design {input.design} --features {params.pairs}"
        " --first-runs {params.runs} --out {params.out} > {log} 2>&1"


rule next_shot_check_calibrations:
    """Every truth calibrated with a model's shots and emulator (`shockcal calibrate-check`, hydrocode truth with
    the truth's lambda_y; one seed stream for every model, so the shots they share see the same noise)."""
    input:
        emulator=rules.next_shot_check_emulator.output.emulator,
        truths=rules.next_shot_check_truths.output.truths,
        features=lambda w: expand(
            rules.features.output[0], run_set="next_shot_truth", shot=PLAN.check_model_shots(w.model)
        ),
    output:
        trials=f"{RESULTS}/next_shot/check/{{model}}/trials.parquet",
        draws=f"{RESULTS}/next_shot/check/{{model}}/draws.parquet",
    log:
        f"{LOGS}/next_shot/check/{{model}}/calibrations.log",
    benchmark:
        f"{BENCHMARKS}/next_shot/check/{{model}}/calibrations.tsv"
    wildcard_constraints:
        model="|".join(re.escape(name) for name in CHECK_MODELS),
    conda:
        "../envs/shockcal.yaml"
    threads: 1
    params:
        settings=lambda w: stage_config(PLAN.check_model_study(w.model), "calibrate_check"),
        config=lambda w: PLAN.check_model_config_option(w.model),
        emulator_dir=lambda w, input: os.path.dirname(input.emulator),
        shots=lambda w: " ".join(PLAN.check_model_shots(w.model)),
        features=lambda w, input: pairs(PLAN.check_model_shots(w.model), input.features),
        trials=CHECK_SECTION["n_truths"],
        n_live=CHECK_SECTION["n_live"],
        n_eff=CHECK_SECTION["n_eff"],
    shell:
        "shockcal calibrate-check {params.config} --emulator {params.emulator_dir} --shots {params.shots}"
        " --truth-design {input.truths} --truth-features {params.features} --trials {params.trials}"
        " --n-live {params.n_live} --n-eff {params.n_eff} --seed-stream next_shot check_noise"
        " --draws-out {output.draws} --out {output.trials} > {log} 2>&1"


rule next_shot_check_summary:
    """Per truth and candidate the realized gain and sds (check.csv); against the ranking's prediction, with the
    verdict (check_summary.csv)."""
    input:
        ranking=rules.suggest_shot.output[0],
        posterior=expand(rules.calibrate.output.samples, name="joint"),
        baseline=expand(rules.next_shot_check_calibrations.output.draws, model="baseline"),
        candidates=expand(rules.next_shot_check_calibrations.output.draws, model=list(PLAN.check_plans)),
    output:
        check=f"{RESULTS}/next_shot/check.csv",
        summary=f"{RESULTS}/next_shot/check_summary.csv",
    log:
        f"{LOGS}/next_shot/check_summary.log",
    benchmark:
        f"{BENCHMARKS}/next_shot/check_summary.tsv"
    conda:
        "../envs/shockcal.yaml"
    params:
        settings=stage_config(config, "next_shot_check_summary"),
        candidates=lambda w, input: pairs(PLAN.check_plans, input.candidates),
    shell:
        "shockcal next-shot-check-summary --ranking {input.ranking} --posterior {input.posterior}"
        " --baseline {input.baseline} --candidates {params.candidates} --out {output.check} > {log} 2>&1"
