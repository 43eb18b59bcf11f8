# Calibrate: single-shot posteriors, the joint posterior, and (target `check`) the synthetic-truth coverage checks.

CALIBRATIONS = [*SHOTS, "joint"]


rule calibrate:
    input:
        emulator=f"{RESULTS}/emulator/emulator.json",
        observed=f"{RESULTS}/features/observed.parquet",
    output:
        samples=f"{RESULTS}/posterior/{{name}}.parquet",
        summary=f"{RESULTS}/posterior/{{name}}_summary.parquet",
    log:
        f"{LOGS}/calibrate/{{name}}.log",
    benchmark:
        f"{BENCHMARKS}/calibrate/{{name}}.tsv"
    wildcard_constraints:
        name="|".join(CALIBRATIONS),
    conda:
        "../envs/shockcal.yaml"
    params:
        calibration=config["calibration"],
        sd_fraction=config["observed"]["sd_fraction"],
        seed=config["study"]["seed"],
        shots=lambda w: " ".join(SHOTS if w.name == "joint" else [w.name]),
        emulator_dir=lambda w, input: os.path.dirname(input.emulator),
    shell:
        "shockcal calibrate --emulator {params.emulator_dir} --shots {params.shots}"
        " --observed {input.observed} --out {output.samples} > {log} 2>&1"


rule calibration_check:
    input:
        emulator=f"{RESULTS}/emulator/emulator.json",
    output:
        f"{RESULTS}/posterior/coverage.parquet",
    log:
        f"{LOGS}/calibrate/coverage.log",
    benchmark:
        f"{BENCHMARKS}/calibrate/coverage.tsv"
    conda:
        "../envs/shockcal.yaml"
    params:
        calibration=config["calibration"],
        sd_fraction=config["observed"]["sd_fraction"],
        seed=config["study"]["seed"],
        emulator_dir=lambda w, input: os.path.dirname(input.emulator),
        shots=" ".join(SHOTS),
    shell:
        "shockcal calibrate-check --emulator {params.emulator_dir} --shots {params.shots}"
        " --out {output} > {log} 2>&1"


rule calibration_check_hydrocode:
    input:
        emulator=f"{RESULTS}/emulator/emulator.json",
        design=f"{RESULTS}/check/design.parquet",
        features=expand(f"{RESULTS}/check/features/{{shot}}.parquet", shot=SHOTS),
    output:
        f"{RESULTS}/posterior/coverage_hydrocode.parquet",
    log:
        f"{LOGS}/calibrate/coverage_hydrocode.log",
    benchmark:
        f"{BENCHMARKS}/calibrate/coverage_hydrocode.tsv"
    conda:
        "../envs/shockcal.yaml"
    params:
        calibration=config["calibration"],
        sd_fraction=config["observed"]["sd_fraction"],
        seed=config["study"]["seed"],
        emulator_dir=lambda w, input: os.path.dirname(input.emulator),
        pairs=lambda w, input: " ".join(f"{s}={f}" for s, f in zip(SHOTS, input.features)),
        shots=" ".join(SHOTS),
    shell:
        "shockcal calibrate-check --emulator {params.emulator_dir} --shots {params.shots}"
        " --truth-design {input.design} --truth-features {params.pairs} --out {output} > {log} 2>&1"


ALL_TARGETS += expand(f"{RESULTS}/posterior/{{name}}_summary.parquet", name=CALIBRATIONS)
CHECK_TARGETS = [f"{RESULTS}/posterior/coverage.parquet", f"{RESULTS}/posterior/coverage_hydrocode.parquet"]


rule check:
    """The synthetic-truth coverage checks (calibration.check.trials each, emulator and hydrocode
    truth): `make check`, outside the default study because of their cost (README)."""
    input:
        CHECK_TARGETS,
