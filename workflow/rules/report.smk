# The report's tables (snakemake --report shows HTML inline; each table also as CSV beside it): posterior
# summaries, evidence, cross-validation, the Sobol indices, the emulator on the posterior's predictive runs,
# and the synthetic-truth coverage when `make check` has made it; with a model discrepancy, its sd in m/s and the
# joint posterior's predictive coverage with it and without it.

from shockcal.inference.discrepancy import enabled as discrepancy_enabled

COVERAGE = existing_coverage(CHECK_TRUTHS, CHECK_TARGETS)


rule report_tables:
    input:
        posteriors=expand(rules.calibrate.output.samples, name=CALIBRATIONS),
        summaries=expand(rules.calibrate.output.summary, name=CALIBRATIONS),
        cv_rmse=rules.emulator.output.rmse,
        sobol=rules.sensitivity.output[0],
    output:
        summary=report(
            f"{RESULTS}/report/posterior_summary.html",
            caption="../report/posterior_summary.rst",
            category="4 posterior",
        ),
        evidence=report(f"{RESULTS}/report/evidence.html", caption="../report/evidence.rst", category="4 posterior"),
        cv=report(
            f"{RESULTS}/report/cross_validation.html",
            caption="../report/cross_validation.rst",
            category="3 emulator",
        ),
        sobol=report(f"{RESULTS}/report/sobol.html", caption="../report/sobol_table.rst", category="6 sensitivity"),
        csv=[f"{RESULTS}/report/{name}.csv" for name in ("posterior_summary", "evidence", "cross_validation")],
    log:
        f"{LOGS}/report_tables.log",
    conda:
        "../envs/shockcal.yaml"
    params:
        posteriors=lambda w, input: pairs(CALIBRATIONS, input.posteriors),
        out_dir=lambda w, output: os.path.dirname(output.summary),
    shell:
        "shockcal report-tables --posteriors {params.posteriors} --cv-rmse {input.cv_rmse} --sobol {input.sobol}"
        " --out-dir {params.out_dir} > {log} 2>&1"


rule report_coverage:
    """The coverage table of `make check`'s merged tables. They are read, not declared as inputs: as inputs they
    would send `all` through the checks again (2 h 45 min on the paper's study) whenever the emulator is
    refitted. Their modification times in `params` rerun the table when a check is redone."""
    output:
        report(f"{RESULTS}/report/coverage.html", caption="../report/coverage.rst", category="4 posterior"),
        f"{RESULTS}/report/coverage.csv",
    log:
        f"{LOGS}/report_coverage.log",
    conda:
        "../envs/shockcal.yaml"
    params:
        coverage=COVERAGE["pairs"],
        modified=COVERAGE["modified"],
        out_dir=lambda w, output: os.path.dirname(output[0]),
    shell:
        "shockcal report-tables --coverage {params.coverage} --out-dir {params.out_dir} > {log} 2>&1"


rule report_heldout:
    """The study's emulator on the posterior's predictive runs, which no fit saw: where the calibration uses it, in
    m/s and in the records' sds (the joint posterior's)."""
    input:
        emulator=rules.emulator.output.emulator,
        design=PLAN.run_set_path("predict", "design.parquet"),
        features=expand(rules.features.output[0], run_set="predict", shot=SHOTS),
        posterior=expand(rules.calibrate.output.samples, name="joint"),
    output:
        report(
            f"{RESULTS}/report/emulator_heldout.html",
            caption="../report/emulator_heldout.rst",
            category="3 emulator",
        ),
        f"{RESULTS}/report/emulator_heldout.csv",
    log:
        f"{LOGS}/report_heldout.log",
    conda:
        "../envs/shockcal.yaml"
    params:
        emulator_dir=lambda w, input: os.path.dirname(input.emulator),
        pairs=lambda w, input: pairs(SHOTS, input.features),
        out_dir=lambda w, output: os.path.dirname(output[0]),
    shell:
        "shockcal report-tables --heldout-emulator {params.emulator_dir} --heldout-design {input.design}"
        " --heldout-features {params.pairs} --heldout-posterior {input.posterior} --out-dir {params.out_dir}"
        " > {log} 2>&1"


rule report_discrepancy:
    """The model discrepancy (calibration.discrepancy) in the report: its sd per calibration, shot and feature in
    m/s, and the joint posterior's predictive 95% bands of the measured features with it and without it (at the
    predict design's posterior draws, from the emulator: no hydrocode run). Thin: `shockcal report-tables`. In
    `all` only for a study with a discrepancy (a posterior without one is refused by --discrepancy)."""
    input:
        posteriors=expand(rules.calibrate.output.samples, name=CALIBRATIONS),
        summaries=expand(rules.calibrate.output.summary, name=CALIBRATIONS),
        design=PLAN.run_set_path("predict", "design.parquet"),
        emulator=rules.emulator.output.emulator,
        arrays=rules.emulator.output.arrays,
    output:
        discrepancy=report(
            f"{RESULTS}/report/discrepancy.html", caption="../report/discrepancy.rst", category="4 posterior"
        ),
        predictive=report(
            f"{RESULTS}/report/predictive_coverage.html",
            caption="../report/predictive_coverage.rst",
            category="4 posterior",
        ),
        csv=[f"{RESULTS}/report/{name}.csv" for name in ("discrepancy", "predictive_coverage")],
    log:
        f"{LOGS}/report_discrepancy.log",
    conda:
        "../envs/shockcal.yaml"
    params:
        posteriors=lambda w, input: pairs(CALIBRATIONS, input.posteriors),
        joint=lambda w, input: input.posteriors[CALIBRATIONS.index("joint")],
        emulator_dir=lambda w, input: os.path.dirname(input.emulator),
        out_dir=lambda w, output: os.path.dirname(output.discrepancy),
    shell:
        "shockcal report-tables --discrepancy {params.posteriors} --predictive-posterior {params.joint}"
        " --predictive-design {input.design} --predictive-emulator {params.emulator_dir}"
        " --out-dir {params.out_dir} > {log} 2>&1"


ALL_TARGETS.extend(rules.report_tables.output)
if discrepancy_enabled(config["calibration"].get("discrepancy")):
    ALL_TARGETS.extend(rules.report_discrepancy.output)
if not PLAN.archive:  # an archive study runs no predictive runs
    ALL_TARGETS.extend(rules.report_heldout.output)
# the coverage checks are outside `all` (make check); their table joins the report once one exists
if COVERAGE["pairs"]:
    ALL_TARGETS.extend(rules.report_coverage.output)
