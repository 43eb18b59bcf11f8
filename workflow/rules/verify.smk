# The hydrocode's verdict on the joint posterior (`make verify`, outside `all`; docs/calibration.md, "The
# hydrocode's verdict"): verify.n_draws seeded joint-posterior draws (stream "verify"), run through the hydrocode
# as the run set "verify" (simulate.smk, features.smk: builtin, command or archive simulators, SLURM), reweighted
# by the hydrocode's likelihood over the emulator's with PSIS.


rule verify_design:
    input:
        posterior=expand(rules.calibrate.output.samples, name="joint"),
    output:
        PLAN.run_set_path("verify", "design.parquet"),
    log:
        f"{LOGS}/verify/design.log",
    benchmark:
        f"{BENCHMARKS}/verify/design.tsv"
    conda:
        "../envs/shockcal.yaml"
    params:
        settings=stage_config(config, "verify_design"),
    shell:
        "shockcal predict --posterior {input.posterior} --stream verify --out {output} > {log} 2>&1"


rule verify:
    """PSIS k-hat of the hydrocode-over-emulator likelihood ratios at the draws, the corrected quantiles, and the
    emulator's error at the draws against the records' sd."""
    input:
        design=rules.verify_design.output[0],
        features=expand(rules.features.output[0], run_set="verify", shot=SHOTS),
        emulator=rules.emulator.output.emulator,
        arrays=rules.emulator.output.arrays,
        observed=rules.observed.output[0],
    output:
        summary=PLAN.run_set_path("verify", "summary.csv"),
        error=PLAN.run_set_path("verify", "emulator_error.csv"),
    log:
        f"{LOGS}/verify/summary.log",
    benchmark:
        f"{BENCHMARKS}/verify/summary.tsv"
    conda:
        "../envs/shockcal.yaml"
    params:
        settings=stage_config(config, "verify"),
        features=lambda w, input: pairs(SHOTS, input.features),
        emulator_dir=lambda w, input: os.path.dirname(input.emulator),
    shell:
        "shockcal verify --design {input.design} --features {params.features} --emulator {params.emulator_dir}"
        " --observed {input.observed} --out {output.summary} --error-out {output.error} > {log} 2>&1"
