# Global sensitivity: Sobol indices (SALib) of each shot's emulated calibration features with respect to
# its inputs, over the prior box and over the box of the joint posterior's 5-95% quantiles (docs/calibration.md).


rule sensitivity:
    input:
        emulator=rules.emulator.output.emulator,
        arrays=rules.emulator.output.arrays,
        summary=expand(rules.calibrate.output.summary, name="joint"),
    output:
        f"{RESULTS}/sensitivity/sobol.csv",  # in the report as report/sobol.html (report.smk)
    log:
        f"{LOGS}/sensitivity.log",
    benchmark:
        f"{BENCHMARKS}/sensitivity.tsv"
    conda:
        "../envs/shockcal.yaml"
    threads: config["emulator"]["n_jobs"]  # the emulator predicts on its n_jobs threads
    params:
        settings=stage_config(config, "sensitivity"),
        emulator_dir=lambda w, input: os.path.dirname(input.emulator),
    shell:
        "shockcal sensitivity --emulator {params.emulator_dir} --posterior-summary {input.summary}"
        " --out {output} > {log} 2>&1"


ALL_TARGETS.append(rules.sensitivity.output[0])
