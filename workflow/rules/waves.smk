# A sequential study (design.strategy: waves; docs/sequential.md). The DAG is static: the wave sizes are
# config keys, so every wave's chunks are known when the workflow is read, and only a wave design's
# content comes from a job: wave k's design reads step k-1's joint posterior (step k: the emulator refitted
# on waves 0..k and the shots recalibrated jointly). A stopped study (design.waves.stop_mcse) writes empty
# wave designs, whose zero-row chunks cost nothing. The last step's emulator and joint posterior are the
# study's own ({RESULTS}/emulator, {RESULTS}/posterior/joint*: emulator.smk, calibrate.smk), so figures,
# predictions and the report read them unchanged. With design.strategy: lhs there are no waves and the
# emulator is fitted on the training runs.
#
#   {RESULTS}/wave{k}/{design.parquet, simulations/, features/}: wave k's runs (the run set "wave{k}")
#   {RESULTS}/waves/step{k}/{design.parquet, features/}: every run of waves 0..k
#   {RESULTS}/waves/step{k}/{emulator/, posterior/}: their emulator and joint posterior (k before the last)
# (the waves, steps and their files: PLAN, src/shockcal/study/workflow_plan.py)

# a step's posterior only places the next wave: a lighter sampler (design.waves.step_calibration)
STEP_SAMPLER = "--n-live {n_live} --n-eff {n_eff}".format(**config["design"]["waves"]["step_calibration"])


rule merge_runs:
    """Every run of waves 0..step: one design, one features table per shot."""
    input:
        designs=lambda w: [PLAN.wave_design_path(k) for k in range(int(w.step) + 1)],
        features=lambda w: PLAN.step_features(w.step),
    output:
        design=PLAN.step_file("{step}", "design"),
        features=[PLAN.step_path("{step}", "features", f"{shot}.parquet") for shot in PLAN.base_shots],
    log:
        f"{LOGS}/waves/step{{step}}/merge_runs.log",
    benchmark:
        f"{BENCHMARKS}/waves/step{{step}}/merge_runs.tsv"
    wildcard_constraints:
        step=r"\d+",
    conda:
        "../envs/shockcal.yaml"
    params:
        settings=stage_config(PLAN.base_study, "merge_runs"),
        pairs=lambda w, input: pairs(PLAN.base_shots * (int(w.step) + 1), input.features),
        out=lambda w: PLAN.step_path(w.step),
    shell:
        "shockcal merge-runs --designs {input.designs} --features {params.pairs} --out {params.out} > {log} 2>&1"


rule wave_emulator:
    """The emulator of every run of waves 0..step (a step before the last: the last is the study's)."""
    input:
        design=rules.merge_runs.output.design,
        features=rules.merge_runs.output.features,
    output:
        emulator=PLAN.step_file("{step}", "emulator"),
        arrays=PLAN.step_file("{step}", "arrays"),
    log:
        f"{LOGS}/waves/step{{step}}/emulator.log",
    benchmark:
        f"{BENCHMARKS}/waves/step{{step}}/emulator.tsv"
    wildcard_constraints:
        step=r"\d+",
    conda:
        "../envs/shockcal.yaml"
    threads: config["emulator"]["n_jobs"]
    params:
        settings=stage_config(PLAN.base_study, "emulate"),
        pairs=lambda w, input: pairs(PLAN.base_shots, input.features),
        out=lambda w, output: os.path.dirname(output.emulator),
    shell:
        "shockcal emulate --design {input.design} --features {params.pairs} --no-cv --out {params.out} > {log} 2>&1"


rule wave_calibrate:
    """The joint posterior of waves 0..step's emulator (a step before the last)."""
    input:
        emulator=rules.wave_emulator.output.emulator,
        observed=rules.observed_base.output[0],
    output:
        samples=PLAN.step_file("{step}", "samples"),
        summary=PLAN.step_file("{step}", "summary"),
        weighted=PLAN.step_file("{step}", "weighted"),
    log:
        f"{LOGS}/waves/step{{step}}/calibrate.log",
    benchmark:
        f"{BENCHMARKS}/waves/step{{step}}/calibrate.tsv"
    wildcard_constraints:
        step=r"\d+",
    conda:
        "../envs/shockcal.yaml"
    threads: 1  # as the study's calibrations (calibrate.smk)
    params:
        settings=stage_config(PLAN.base_study, "calibrate"),
        sampler=STEP_SAMPLER,
        shots=" ".join(PLAN.base_shots),
        emulator_dir=lambda w, input: os.path.dirname(input.emulator),
    shell:
        "shockcal calibrate --emulator {params.emulator_dir} --shots {params.shots} {params.sampler}"
        " --observed {input.observed} --out {output.samples} > {log} 2>&1"


rule wave_design:
    """A later wave's design: the previous joint posterior thinned (design.waves.criterion), or no runs
    once the posterior stopped moving (design.waves.stop_mcse)."""
    input:
        unpack(lambda w: PLAN.wave_design_inputs(w.wave)),
    output:
        f"{RESULTS}/wave{{wave}}/design.parquet",
    log:
        f"{LOGS}/wave{{wave}}/design.log",
    benchmark:
        f"{BENCHMARKS}/wave{{wave}}/design.tsv"
    wildcard_constraints:
        wave=r"[1-9]\d*",
    conda:
        "../envs/shockcal.yaml"
    params:
        settings=stage_config(PLAN.base_study, "wave_design"),
        earlier=lambda w, input: f"--earlier-summary {input.earlier}" if "earlier" in input.keys() else "",
        emulator_dir=lambda w, input: os.path.dirname(input.emulator),
    shell:
        "shockcal wave-design --wave {wildcards.wave} --posterior {input.posterior} {params.earlier}"
        " --previous-design {input.previous} --runs {input.runs} --emulator {params.emulator_dir}"
        " --observed {input.observed} --out {output} > {log} 2>&1"


rule new_shot_design:
    """A new shot's design (design.new_shots): the base shots' joint posterior of the last step (step 0, the
    training runs alone, without waves) thinned, the shot's own inputs drawn fresh. Its settings are the base
    study's and this shot's alone (`new_shot_config`), so adding another shot reruns none of its runs."""
    input:
        posterior=PLAN.step_file(PLAN.last_step, "samples"),
        runs=PLAN.step_file(PLAN.last_step, "design"),
    output:
        PLAN.run_set_path("new_shot", "designs", "{shot}.parquet"),
    log:
        f"{LOGS}/new_shot/design/{{shot}}.log",
    benchmark:
        f"{BENCHMARKS}/new_shot/design/{{shot}}.tsv"
    wildcard_constraints:
        shot="|".join(PLAN.new_shots) or "^$",
    conda:
        "../envs/shockcal.yaml"
    params:
        settings=lambda w: stage_config(new_shot_config(config, w.shot), "new_shot_design", w.shot),
    shell:
        "shockcal new-shot-design --shot {wildcards.shot} --posterior {input.posterior} --runs {input.runs}"
        " --out {output} > {log} 2>&1"
