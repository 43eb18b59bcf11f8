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
#   verify:   verify.n_draws seeded joint-posterior draws, the hydrocode's verdict (`make verify`; verify.smk);
#   check:    calibration.check.trials truths on a Latin hypercube over the box, for the synthetic-truth
#             check with hydrocode-made pseudo-measurements (calibrate.smk);
#   next_shot: next_shot.n_draws joint-posterior draws at each next-shot candidate, whose names take the
#             shots' place ({RESULTS}/next_shot/simulations/<candidate>/; next_shot.smk);
#   wave1, wave2, ...: a sequential study's later waves (design.strategy: waves; waves.smk), their sizes
#             fixed by the config, their designs made by jobs from the previous wave's joint posterior;
#             the training run set is then wave 0.


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
    "check_posterior": config["calibration"]["check"]["trials"],
    "next_shot": config["next_shot"]["n_draws"],
    "verify": config["verify"]["n_draws"],  # the hydrocode's verdict (verify.smk)
}
WAVES = [f"wave{k}" for k in range(1, len(wave_sizes(config)))]  # none with design.strategy: lhs
RUN_SET_SIZES.update(zip(WAVES, wave_sizes(config)[1:]))

# The next-shot check (next_shot_check.smk): each compared candidate as the fourth shot of a study derived from
# the config (its config file and training design: the study's, the candidate's inputs drawn as new columns),
# planned here as the training design is. Without a ranking yet, or with settings that do not fit the study, there
# is none, unless the check is a target on the command line (its rule, or a file of its own; snakemake has not read
# its targets yet when it reads this file): then it stops with one line.
try:
    CHECK_PLANS = plan_check(
        config,
        f"{RESULTS}/next_shot/ranking.csv",
        DESIGN,
        run_set_path("next_shot_check"),
        required=any("next_shot_check" in word or "next_shot/check" in word for word in sys.argv[1:]),
    )
except ShockcalError as exc:
    raise SystemExit(f"shockcal: error: {exc}") from None
CHECK_DIGESTS = {
    name: chunk_fingerprints(plan["table"][["run", *shot_mapping(plan["study"], name).inputs()]], CHUNK_SIZE)
    for name, plan in CHECK_PLANS.items()
}
#   next_shot_check: the compared candidates' training runs, the first next_shot.check.n_training_runs rows of
#             their derived studies' designs; next_shot_truth: the check's truths at the shots and the candidates.
RUN_SET_SIZES["next_shot_check"] = config["next_shot"]["check"]["n_training_runs"]
RUN_SET_SIZES["next_shot_truth"] = config["next_shot"]["check"]["n_truths"]
#   new_shot: design.new_shots.n_runs rows per new shot, from the base shots' joint posterior (waves.smk), each
#             shot's own design ({RESULTS}/new_shot/designs/<shot>.parquet)
RUN_SET_SIZES["new_shot"] = config["design"]["new_shots"]["n_runs"]
# Rows per simulate chunk: simulate.chunk_size; a new shot's, one shot alone, in NEW_SHOT_CHUNKS chunks at most that
# size, so that its runs fill the cores (150 runs in one chunk of the paper study's 150 kept one core idle)
NEW_SHOT_CHUNKS = 4
RUN_SET_CHUNK_SIZE = {name: CHUNK_SIZE for name in RUN_SET_SIZES}
RUN_SET_CHUNK_SIZE["new_shot"] = min(CHUNK_SIZE, chunk_count(RUN_SET_SIZES["new_shot"], NEW_SHOT_CHUNKS))
RUN_SET_CHUNKS = {name: list(range(chunk_count(n, RUN_SET_CHUNK_SIZE[name]))) for name, n in RUN_SET_SIZES.items()}
