# Design: the seeded Latin hypercube over the prior box, or the config's design file (checked
# against it). It is made here, when the workflow is read, not by a job: the chunks are planned from
# it, and `write_design` rewrites results/design.parquet only when its content changes. (A design
# job would be an `ancient` input of every chunk, and snakemake drops the jobs downstream of an
# `ancient` input whose producer reruns in the same invocation, snakemake/snakemake#4166: appended
# rows ran on the second call only.) `shockcal design` writes the same table outside the workflow.
#
# Run sets: every set of hydrocode runs goes through the same rules (simulate.smk, features.smk) and
# the same paths, {RESULTS}/{run_set}/{design.parquet, simulations/, features/}, in chunks of
# simulate.chunk_size design rows:
#   training: the design below, for the emulator;
#   predict:  predict.n_posterior_runs seeded joint-posterior draws (Figs 10-13; predict.smk);
#   check:    calibration.check.trials truths on a Latin hypercube over the box, for the synthetic-truth
#             check with hydrocode-made pseudo-measurements (calibrate.smk);
#   next_shot: next_shot.n_draws joint-posterior draws at each next-shot candidate, whose names take the
#             shots' place ({RESULTS}/next_shot/simulations/<candidate>/; next_shot.smk).


DESIGN = run_set_path("training", "design.parquet")
_PLANNED_DESIGN, _DESIGN_SOURCE = study_design(config)
write_design(_PLANNED_DESIGN, _DESIGN_SOURCE, input_box(config), DESIGN)
# a digest per shot and chunk, over the run ids and the columns that shot reads: a column added for
# a new shot (its impact velocity) leaves every other shot's chunks alone
CHUNK_DIGESTS = {
    shot: chunk_fingerprints(_PLANNED_DESIGN[["run", *shot_mapping(config, shot).inputs()]], CHUNK_SIZE)
    for shot in SHOTS
}
RUN_SET_SIZES = {
    "training": len(_PLANNED_DESIGN),
    "predict": config["predict"]["n_posterior_runs"],
    "check": config["calibration"]["check"]["trials"],
    "next_shot": config["next_shot"]["n_draws"],
}
RUN_SET_CHUNKS = {name: list(range(chunk_count(n, CHUNK_SIZE))) for name, n in RUN_SET_SIZES.items()}
