# Calibrate: single-shot posteriors, the joint posterior, and (target `check`) the synthetic-truth coverage checks.

CALIBRATIONS = [*SHOTS, "joint"]


rule calibrate:
    input:
        emulator=rules.emulator.output.emulator,
        observed=rules.observed.output[0],
    output:
        samples=f"{RESULTS}/posterior/{{name}}.parquet",
        summary=f"{RESULTS}/posterior/{{name}}_summary.parquet",
        weighted=f"{RESULTS}/posterior/{{name}}_weighted.parquet",
    log:
        f"{LOGS}/calibrate/{{name}}.log",
    benchmark:
        f"{BENCHMARKS}/calibrate/{{name}}.tsv"
    wildcard_constraints:
        name="|".join(CALIBRATIONS),
    priority: lambda w: 10 if w.name == "joint" else 0  # the joint posterior first: a new shot's answer
    conda:
        "../envs/shockcal.yaml"
    # one core: nautilus's bounds and network training are serial (CPU 0.79 of wall time on the sequential
    # study's calibrations); the emulator's n_jobs prediction threads take 5% of it, so calibrations run
    # beside each other and the simulate chunks (the joint 52 s against 54.5 s with one thread: docs/workflow.md)
    threads: 1
    params:
        settings=stage_config(config, "calibrate"),
        shots=lambda w: " ".join(SHOTS if w.name == "joint" else [w.name]),
        emulator_dir=lambda w, input: os.path.dirname(input.emulator),
    shell:
        "shockcal calibrate --emulator {params.emulator_dir} --shots {params.shots}"
        " --observed {input.observed} --out {output.samples} > {log} 2>&1"


CHECK = config["calibration"]["check"]
CHECK_BATCHES = list(range(chunk_count(CHECK["trials"], CHECK["trials_per_job"])))
CHECK_TRUTHS = ["emulator", "hydrocode", "posterior"]
# the hydrocode runs each truth reads: hydrocode truth a Latin hypercube over the box, posterior truth draws from the
# joint posterior (docs/calibration.md, "Posterior truth")
TRUTH_RUN_SETS = {"hydrocode": "check", "posterior": "check_posterior"}


rule check_design:
    """The hydrocode-truth check's truths: a Latin hypercube over the box (run set "check")."""
    output:
        PLAN.run_set_path("check", "design.parquet"),
    log:
        f"{LOGS}/check/design.log",
    benchmark:
        f"{BENCHMARKS}/check/design.tsv"
    conda:
        "../envs/shockcal.yaml"
    params:
        settings=stage_config(config, "check_design"),
    shell:
        "shockcal design --stream check_design --out {output} > {log} 2>&1"


rule check_posterior_design:
    """The posterior-truth check's truths: calibration.check.trials joint-posterior draws, each with its
    lambda_y (run set "check_posterior"; seed stream check_posterior, apart from the predictive runs')."""
    input:
        posterior=expand(rules.calibrate.output.samples, name="joint"),
    output:
        PLAN.run_set_path("check_posterior", "design.parquet"),
    log:
        f"{LOGS}/check/posterior_design.log",
    benchmark:
        f"{BENCHMARKS}/check/posterior_design.tsv"
    conda:
        "../envs/shockcal.yaml"
    params:
        settings=stage_config(config, "check_posterior_design"),
    shell:
        "shockcal predict --posterior {input.posterior} --stream check_posterior --out {output} > {log} 2>&1"


rule calibration_check_batch:
    """One batch of synthetic-truth trials (each trial has its own random stream, so batches are
    independent jobs and together give what one run of every trial gives)."""
    input:
        # hydrocode and posterior truth also read their truths' design and features (TRUTH_RUN_SETS)
        unpack(
            lambda w: (
                {}
                if w.truth == "emulator"
                else {
                    "design": PLAN.run_set_path(TRUTH_RUN_SETS[w.truth], "design.parquet"),
                    "features": expand(rules.features.output[0], run_set=TRUTH_RUN_SETS[w.truth], shot=SHOTS),
                }
            )
        ),
        emulator=rules.emulator.output.emulator,
    output:
        f"{RESULTS}/check/coverage/{{truth}}/batch-{{batch}}.parquet",
    log:
        f"{LOGS}/check/coverage/{{truth}}/batch-{{batch}}.log",
    benchmark:
        f"{BENCHMARKS}/check/coverage/{{truth}}/batch-{{batch}}.tsv"
    wildcard_constraints:
        truth="|".join(CHECK_TRUTHS),
        batch=r"\d+",
    conda:
        "../envs/shockcal.yaml"
    # one core per batch, so batches run side by side: a batch keeps only 1.2 cores busy (nautilus's
    # network training is serial), and two at a time on 2 cores give 1.7x the trials per hour (docs/calibration.md)
    threads: 1
    params:
        settings=stage_config(config, "calibrate_check"),
        emulator_dir=lambda w, input: os.path.dirname(input.emulator),
        shots=" ".join(SHOTS),
        trial_range=lambda w: chunk_rows(w.batch, CHECK["trials_per_job"], CHECK["trials"]),
        truth=lambda w, input: (
            ""
            if w.truth == "emulator"
            else f"--truth-design {input.design} --truth-features {pairs(SHOTS, input.features)}"
        ),
    shell:
        "shockcal calibrate-check --emulator {params.emulator_dir} --shots {params.shots} {params.truth}"
        " --trial-range {params.trial_range} --out {output} > {log} 2>&1"


rule coverage:
    """Every batch of one check merged: one row per trial and parameter; the log has the coverage table."""
    input:
        expand(rules.calibration_check_batch.output[0], batch=CHECK_BATCHES, allow_missing=True),
    output:
        f"{RESULTS}/posterior/coverage_{{truth}}.parquet",
    log:
        f"{LOGS}/calibrate/coverage_{{truth}}.log",
    wildcard_constraints:
        truth="|".join(CHECK_TRUTHS),
    conda:
        "../envs/shockcal.yaml"
    shell:
        "shockcal coverage --trials {input} --out {output} > {log} 2>&1"


ALL_TARGETS += expand(rules.calibrate.output.summary, name=CALIBRATIONS)
CHECK_TARGETS = expand(rules.coverage.output[0], truth=CHECK_TRUTHS)


rule check:
    """The synthetic-truth coverage checks (calibration.check.trials each; emulator, hydrocode and
    posterior truth): `make check`, outside the default study because of their cost (README)."""
    input:
        CHECK_TARGETS,
