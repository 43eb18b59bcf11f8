# Calibrate: single-shot posteriors, the joint posterior, and the synthetic-truth coverage check.

CALIBRATIONS = [*SHOTS, "joint"]


def calibration_shots(wildcards):
    return " ".join(SHOTS if wildcards.name == "joint" else [wildcards.name])


rule calibrate:
    input:
        emulator=f"{RESULTS}/emulator/emulator.json",
        observed=f"{RESULTS}/features/observed.parquet",
    output:
        samples=f"{RESULTS}/posterior/{{name}}.parquet",
        summary=f"{RESULTS}/posterior/{{name}}_summary.parquet",
    wildcard_constraints:
        name="|".join(CALIBRATIONS),
    params:
        calibration=config["calibration"],
        sd_fraction=config["observed"]["sd_fraction"],
        seed=config["study"]["seed"],
        shots=calibration_shots,
        emulator_dir=f"{RESULTS}/emulator",
    log:
        log_file("calibrate/{name}"),
    benchmark:
        benchmark_file("calibrate/{name}")
    conda:
        "../envs/shockcal.yaml"
    shell:
        "shockcal calibrate --config {EFFECTIVE_CONFIG} --emulator {params.emulator_dir} --shots {params.shots}"
        " --observed {input.observed} --out {output.samples} > {log} 2>&1"


rule calibration_check:
    input:
        emulator=f"{RESULTS}/emulator/emulator.json",
    output:
        f"{RESULTS}/posterior/coverage.parquet",
    params:
        calibration=config["calibration"],
        sd_fraction=config["observed"]["sd_fraction"],
        seed=config["study"]["seed"],
        emulator_dir=f"{RESULTS}/emulator",
    log:
        log_file("calibrate/coverage"),
    benchmark:
        benchmark_file("calibrate/coverage")
    conda:
        "../envs/shockcal.yaml"
    shell:
        "shockcal calibrate-check --config {EFFECTIVE_CONFIG} --emulator {params.emulator_dir} --shots {SHOTS}"
        " --out {output} > {log} 2>&1"


rule calibration_check_hydrocode:
    input:
        emulator=f"{RESULTS}/emulator/emulator.json",
        design=f"{RESULTS}/check/design.parquet",
        features=expand(f"{RESULTS}/check/features/{{shot}}.parquet", shot=SHOTS),
    output:
        f"{RESULTS}/posterior/coverage_hydrocode.parquet",
    params:
        calibration=config["calibration"],
        sd_fraction=config["observed"]["sd_fraction"],
        seed=config["study"]["seed"],
        emulator_dir=f"{RESULTS}/emulator",
        pairs=lambda w, input: " ".join(f"{s}={f}" for s, f in zip(SHOTS, input.features)),
    log:
        log_file("calibrate/coverage_hydrocode"),
    benchmark:
        benchmark_file("calibrate/coverage_hydrocode")
    conda:
        "../envs/shockcal.yaml"
    shell:
        "shockcal calibrate-check --config {EFFECTIVE_CONFIG} --emulator {params.emulator_dir} --shots {SHOTS}"
        " --truth-design {input.design} --truth-features {params.pairs} --out {output} > {log} 2>&1"


ALL_TARGETS += expand(f"{RESULTS}/posterior/{{name}}_summary.parquet", name=CALIBRATIONS)
ALL_TARGETS += [f"{RESULTS}/posterior/coverage.parquet", f"{RESULTS}/posterior/coverage_hydrocode.parquet"]
