"""The Snakemake workflow on the quick study: every figure from one command, partial reruns decided
by config slices (not mtimes), and an interrupted fan-out finishing with identical results.

One quick study (config/quick.yaml, about two minutes on 2 idle cores) is run into a temporary results
directory and shared by the tests of the session (`quick_study`, tests/conftest.py); the rerun checks
are dry runs against it.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import matplotlib.image
import numpy as np
import pandas as pd
import pytest
import yaml

from shockcal.study.figure_catalogue import catalogue
from shockcal.study.read_log import READ_LOG
from shockcal.study.validate import load_config

REPO = Path(__file__).resolve().parents[1]
SNAKEMAKE = str(Path(sys.executable).parent / "snakemake")


def snakemake(*args, config_files=(), check=True, read_log=None, **popen):
    """Run snakemake in the repository with config/quick.yaml plus `config_files` (targets first:
    --configfile takes every argument after it); with `read_log`, its commands log there the keys of their
    config slices they read (`unread_keys`)."""
    command = [SNAKEMAKE, *args, "--configfile", "config/quick.yaml", *map(str, config_files)]
    if popen:   # Ctrl-C must reach it even when the tests run in a background job, which ignores SIGINT
        return subprocess.Popen(command, cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                                preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL), **popen)
    env = None if read_log is None else {**os.environ, READ_LOG: str(read_log)}
    done = subprocess.run(command, cwd=REPO, capture_output=True, text=True, env=env)
    if check and done.returncode != 0:
        pytest.fail(f"snakemake {' '.join(args)} failed:\n{done.stdout[-3000:]}\n{done.stderr[-3000:]}")
    return done


def overlay(path: Path, **sections) -> Path:
    path.write_text(yaml.safe_dump(sections))
    return path


def pending_jobs(*config_files, target="all") -> dict[str, int]:
    """Rule -> number of jobs a dry run of `target` would execute (empty when nothing is to be done).
    Jobs of the run-set rules count under the rule's name for the training runs and under
    "rule[run set]" for the others ("simulate[predict]"), so a rerun of training runs stays visible."""
    return job_counts(snakemake(target, "--dry-run", config_files=config_files).stdout)


def job_counts(out: str) -> dict[str, int]:
    """`pending_jobs`' count from a dry run's output."""
    if "Job stats:" not in out:
        assert "Nothing to be done" in out, out[-2000:]
        return {}
    jobs = {}
    for block in re.split(r"^(?=(?:local)?rule \S+:$)", out, flags=re.MULTILINE)[1:]:
        rule = re.match(r"(?:local)?rule (\S+):", block).group(1)
        run_set = re.search(r"^\s+wildcards:.*\brun_set=(\w+)", block, flags=re.MULTILINE)
        key = rule if run_set is None or run_set.group(1) == "training" else f"{rule}[{run_set.group(1)}]"
        jobs[key] = jobs.get(key, 0) + 1
    total = int(re.search(r"^total\s+(\d+)$", out, flags=re.MULTILINE).group(1))
    assert sum(jobs.values()) == total, (jobs, out[-2000:])
    return jobs


@pytest.fixture
def study(quick_study):
    """The session's quick study (tests/conftest.py): (results directory, its config overlay)."""
    return quick_study


def unread_keys(folder: Path) -> tuple[dict[str, list[str]], set[str]]:
    """From a read log (shockcal.study.read_log): the keys each stage declared that none of its jobs read (over
    its jobs: one job reads one shot's keys), and the stages logged (a figure is a stage of its own)."""
    declared: dict[str, set] = {}
    read: dict[str, set] = {}
    for log in folder.glob("*.json"):
        entry = json.loads(log.read_text())
        declared.setdefault(entry["stage"], set()).update(entry["declared"])
        read.setdefault(entry["stage"], set()).update(entry["reads"])
    return {stage: sorted(keys - read[stage]) for stage, keys in declared.items() if keys - read[stage]}, set(declared)


# keys the quick study's next shot leaves unread that a stage reads elsewhere: on a branch it does not take, or as
# part of a section it reads in part and declares whole
NOT_READ_HERE = {
    "suggest_shot": ("material.T_ref_K",),                    # a candidate without initial_temperature_K
    "calibrate_check": ("calibration.check.trials",),          # the command without --trial-range
    "next_shot_simulate": ("inputs.",),                        # the units of the strength inputs alone
    "next_shot_features": ("material.", "inputs."),            # a window scaled by the plateau: the Hugoniot, the
                                                               # reference shot's modulus box
    "next_shot_check_summary": ("inputs.",),                   # the law's parameters among the inputs' names,
    "figure next_shot": ("inputs.",),                          # asked for by name (`strength_parameters`)
}


def test_every_declared_key_is_read_by_its_jobs(study, quick_study_reads):
    """A stage's declared keys are its rule's params (a change reruns it): each is read by a job of the stage
    or it reruns jobs for nothing. Each command of the quick study logged the keys of its slice it read."""
    unread, declared = unread_keys(quick_study_reads)
    assert not unread, f"declared and never read (stage: keys): {unread}"
    commands = {stage for stage in declared if not stage.startswith("figure ")}
    assert {"simulate", "features", "observed", "emulate", "calibrate", "predict", "sensitivity"} <= commands
    made = [spec for spec in catalogue(load_config("config/quick.yaml")).values() if spec.target == "all"]
    assert len(declared) - len(commands) == len(made)      # every figure of the study


def test_every_figure_is_a_real_image(study):
    results, _ = study
    config = load_config(REPO / "config" / "config.yaml")
    names = [name for name, spec in catalogue(config).items() if spec.target == "all"]
    assert len(names) == 17     # the paper's fifteen, the Sobol indices and the measured features against the training runs
    for name in names:
        png, pdf = results / "figures" / f"{name}.png", results / "figures" / f"{name}.pdf"
        image = matplotlib.image.imread(png)
        assert image.shape[0] > 300 and image.shape[1] > 300, name
        assert np.std(image[..., :3]) > 0.05, f"{name} is (nearly) blank"
        assert pdf.read_bytes()[:5] == b"%PDF-", name


def test_study_products(study):
    results, _ = study
    usable = None
    for shot in ("104S", "105S", "106S"):
        features = pd.read_parquet(results / "training" / "features" / f"{shot}.parquet")
        assert len(features) == 40 and (features["status"] == "ok").mean() >= 0.95
        ok = set(features.loc[features["status"] == "ok", "run"])
        usable = ok if usable is None else usable & ok
    for name in ("104S", "105S", "106S", "joint"):
        summary = pd.read_parquet(results / "posterior" / f"{name}_summary.parquet")
        assert {"mean", "sd", "q05", "q95", "ess"} <= set(summary.columns), summary.columns
    cv = pd.read_parquet(results / "emulator" / "cv.parquet")
    assert len(cv) == len(usable) * 12                        # failed runs are excluded, not lost


def test_report(study, tmp_path):
    results, config = study
    report = tmp_path / "report.html"
    snakemake("all", "--report", str(report), config_files=[config])
    text = report.read_text(errors="replace")
    assert "fig07_marginals" in text and "fig11_history_104S" in text and "sobol_indices" in text
    for table in ("posterior_summary", "evidence", "cross_validation", "sobol"):    # the tables, shown inline
        assert f"{table}.html" in text, table
    assert "Where to look" in text                            # the workflow description (workflow/report/workflow.rst)


def test_netcdf_and_sobol_products(study):
    import arviz as az

    results, _ = study
    for name in ("104S", "105S", "106S", "joint"):
        idata = az.from_netcdf(results / "posterior" / f"{name}.nc")
        assert "lambda_y" in idata.posterior and "log_evidence" in idata.attrs
    assert "posterior_predictive" in az.from_netcdf(results / "posterior" / "joint.nc").groups()
    sobol = pd.read_csv(results / "sensitivity" / "sobol.csv")
    assert list(sobol.columns) == ["domain", "shot", "feature", "input", "S1", "S1_conf", "ST", "ST_conf"]
    assert set(sobol["domain"]) == {"prior", "posterior_q05_q95"} and sobol["ST"].between(-0.1, 1.2).all()


@pytest.mark.slow   # 40-60 s on 2 cores (4 simulate and 4 feature jobs, 33 CPU s in all); tests/test_candidates.py is the fast check
def test_next_shot_target_ranks_the_quick_candidates(study):
    """`snakemake next_shot` on the quick study: two candidates (104S's plates at 298 and 600 K), 20 joint-posterior
    draws each through the hydrocode as the run set next_shot, ranked into next_shot/ranking.csv with its figure;
    `all` is left untouched."""
    results, config = study
    snakemake("next_shot", "--cores", "2", config_files=[config])
    ranking = pd.read_csv(results / "next_shot" / "ranking.csv")
    assert set(ranking["candidate"]) == {"104S-3.95x5.965mm-204ms-298K", "104S-3.95x5.965mm-204ms-600K"}
    assert ranking["eig_nats"].is_monotonic_decreasing and list(ranking["rank"]) == [1, 2]
    assert (ranking["n_draws"] + ranking["n_failed"] == 20).all() and np.isfinite(ranking["eig_nats"]).all()
    assert (ranking["eig_sd"] > 0).all() and (ranking["noise_sd_v_elastic"] > 0).all()
    assert {f"expected_sd_{p}" for p in ("A", "B", "C", "n", "m")} <= set(ranking.columns)
    for chunk in (0, 1):          # fanned out per candidate and chunk like any run set
        assert (results / "next_shot" / "simulations" / ranking["candidate"][0] / f"chunk-{chunk}.parquet").is_file()
    assert matplotlib.image.imread(results / "figures" / "next_shot.png").shape[0] > 300
    assert pending_jobs(config) == {} and pending_jobs(config, target="next_shot") == {}


def test_nothing_to_redo(study):
    assert pending_jobs(study[1]) == {}


@pytest.fixture(scope="module")
def sampler_change(quick_study, tmp_path_factory):
    """One dry run (each costs seconds of snakemake's start) with another sampler setting, read by the two tests
    below: where the effective settings' link pointed before it, and the jobs it would run."""
    results, config = quick_study
    pointed = (results / "config" / "effective.yaml").resolve()
    return pointed, pending_jobs(config, overlay(tmp_path_factory.mktemp("sampler") / "sampler.yaml",
                                                 calibration={"n_eff": 600}))


def test_the_settings_of_the_last_run_have_a_stable_path(study, sampler_change):
    """{results}/config/effective.yaml points at the content-named config the run's jobs read; a dry run with
    other settings writes its own content-named file and leaves the link (and the running jobs' file) alone."""
    results, config = study
    link = results / "config" / "effective.yaml"
    assert link.is_symlink() and re.fullmatch(r"effective-[0-9a-f]{12}\.yaml", os.readlink(link)), os.readlink(link)
    pointed, jobs = sampler_change
    assert load_config(link)["design"]["n_runs"] == 40 and load_config(link)["study"]["results_dir"] == str(results)
    assert jobs
    assert link.resolve() == pointed and len(list(link.parent.glob("effective-*.yaml"))) >= 2


def test_sampler_setting_reruns_no_simulation(sampler_change):
    _, jobs = sampler_change
    assert jobs.get("calibrate") == 4
    assert not {"design", "simulate", "features_chunk", "features", "emulator"} & set(jobs), jobs


def test_physics_setting_reruns_every_simulation(study, tmp_path):
    jobs = pending_jobs(study[1], overlay(tmp_path / "physics.yaml", hydro={"q_linear": 0.12}))
    assert jobs["simulate"] == 12 and jobs["features_chunk"] == 12 and jobs["features"] == 3 and jobs["emulator"] == 1
    assert "design" not in jobs


def test_added_design_rows_run_only_new_chunks(study, tmp_path):
    results, config = study
    design = pd.read_parquet(results / "training" / "design.parquet")
    extra = design.tail(10).copy()
    extra["run"] += 10
    extra["A"] *= 0.9
    grown = tmp_path / "design.parquet"
    pd.concat([design, extra]).to_parquet(grown)
    jobs = pending_jobs(config, overlay(tmp_path / "grown.yaml", design={"file": str(grown)}))
    assert jobs["simulate"] == 3 and jobs["features_chunk"] == 3     # chunk 4 of each shot
    assert jobs["features"] == 3 and jobs["emulator"] == 1


def test_added_shot_runs_only_its_simulations(study, tmp_path):
    quick = load_config(REPO / "config" / "config.yaml")
    new_shot = dict(quick["shots"]["106S"], target_mm=4.0)
    record = _own_record(quick, tmp_path)                        # a fourth shot comes with its record
    more = overlay(tmp_path / "shot.yaml", shots={"107S": new_shot}, observed={"records": {"107S": record}})
    jobs = pending_jobs(study[1], more)
    assert "simulate" not in jobs and "features" not in jobs          # no training run reruns
    assert jobs["simulate[new_shot]"] == jobs["features_chunk[new_shot]"] == 4 and jobs["features[new_shot]"] == 1
    assert jobs["wave_emulator"] == jobs["wave_calibrate"] == 1       # the base shots' step 0 places 107S's runs


def _own_record(config, tmp_path) -> dict:
    """A record file of the added shot's own: a copy of 106S's (one file for two shots is refused)."""
    path = tmp_path / "Data_S107S.txt"
    shutil.copy(REPO / config["observed"]["records"]["106S"]["path"], path)
    return {**config["observed"]["records"]["106S"], "path": str(path)}


def params_changed(*config_files) -> set[str]:
    """Rules with an output whose recorded params differ from what the config gives now
    (`snakemake --summary`: output, date, rule, log, status, plan)."""
    rows = [line.split("\t") for line in snakemake("--summary", config_files=config_files).stdout.splitlines()[1:]]
    return {row[2] for row in rows if len(row) > 4 and row[4] == "params changed"}


def test_a_seed_change_reaches_exactly_the_seeded_stages(study, tmp_path):
    """Every stage that draws from a random stream of study.seed (shockcal.seeds) lists the seed in
    its params, and no other does (the drift this guards against: the extractor once seeded from study.seed while
    its rule did not list it). The design is fixed by a file so that only the seed differs."""
    results, config = study
    design = tmp_path / "design.parquet"
    shutil.copy(results / "training" / "design.parquet", design)
    fixed = overlay(tmp_path / "fixed.yaml", design={"file": str(design)})
    reseeded = overlay(tmp_path / "seed.yaml", study={"seed": 7})
    flagged = params_changed(config, fixed, reseeded) - params_changed(config, fixed)
    histories = {f"figure_fig{n}_history_{shot}" for n, shot in [(11, "104S"), (12, "105S"), (13, "106S")]}
    # posterior_netcdf: its config_digest attribute is the calibrate slice's, seed included; observed: the
    # read-out bootstrap's `readout` stream
    assert flagged == {"observed", "emulator", "calibrate", "predict_design", "posterior_netcdf", "sensitivity",
                       *histories}, flagged


def test_observation_error_reaches_exactly_the_stages_that_use_it(study, tmp_path):
    """observed.sd_fraction sets the calibrations' likelihood and the error bars of Figures 9-10 and
    features_vs_training, and nothing else: the declared slices (shockcal.study.stages) list it there and only there. Until the
    declaration the two figures did not list it and were left stale by a change."""
    results, config = study
    wider = overlay(tmp_path / "sd.yaml", observed={"sd_fraction": 0.02})
    flagged = params_changed(config, wider) - params_changed(config)
    assert flagged == {"calibrate", "posterior_netcdf", "figure_fig09_features_emulator",
                       "figure_fig10_features_hydrocode", "figure_features_vs_training"}, flagged


def test_coverage_checks_fan_out_in_batches_of_trials(study):
    # quick.yaml: 4 trials per check, 2 per job -> 2 batch jobs per truth (emulator, hydrocode, posterior), one merge
    # each; the hydrocode truths' runs over the box and the posterior truths' runs from the joint posterior, no
    # training run and no refit
    jobs = pending_jobs(study[1], target="check")
    assert jobs["calibration_check_batch"] == 6 and jobs["coverage"] == 3, jobs
    assert jobs["check_design"] == jobs["check_posterior_design"] == 1, jobs
    assert jobs["simulate[check]"] == jobs["simulate[check_posterior]"] == 3, jobs
    assert "emulator" not in jobs and "simulate" not in jobs and "calibrate" not in jobs, jobs


def test_deleted_intermediates_rerun_only_their_dependents(study):
    """A deleted simulation chunk reruns that chunk, its features and what depends on them; a deleted
    features table reruns its shot's merge and what follows, and no simulation or extraction."""
    results, config = study
    chunk = results / "training" / "simulations" / "104S" / "chunk-1.parquet"
    features = results / "training" / "features" / "105S.parquet"
    kept = {path: path.with_name(path.name + ".kept") for path in (chunk, features)}
    for path, aside in kept.items():
        path.rename(aside)
    try:
        jobs = pending_jobs(config)
    finally:
        for path, aside in kept.items():
            aside.rename(path)
    assert jobs["simulate"] == 1 and jobs["features_chunk"] == 1 and jobs["features"] == 2, jobs
    assert jobs["emulator"] == 1, jobs
    assert pending_jobs(config) == {}


def test_added_shot_with_its_own_velocity_runs_only_its_simulations(study, tmp_path):
    """A fourth shot as a user adds one: its own impact-velocity input (a new design column, given in
    a design file) and its record. Only its chunks are simulated; the other shots' are untouched."""
    results, config = study
    quick = load_config(REPO / "config" / "config.yaml")
    design = pd.read_parquet(results / "training" / "design.parquet")
    box = quick["inputs"]["V3"]
    design["V4"] = np.random.default_rng(1).uniform(box["min"], box["max"], len(design))
    grown = tmp_path / "design.parquet"
    design.to_parquet(grown)
    shot = dict(quick["shots"]["106S"], target_mm=4.0, velocity_input="V4")
    more = overlay(tmp_path / "shot.yaml", design={"file": str(grown), "new_shots": {"runs_from": "training"}}, inputs={"V4": box},
                   shots={"107S": shot}, observed={"records": {"107S": _own_record(quick, tmp_path)}})
    jobs = pending_jobs(config, more)
    assert jobs["simulate"] == jobs["features_chunk"] == 4 and jobs["features"] == 1, jobs   # 107S's 4 chunks


def test_a_shot_added_by_config_alone_runs_only_its_simulations(study, tmp_path):
    """Adding a shot is a config edit: its own impact velocity and modulus increment under `inputs`,
    the shot and its record. With `design.new_shots.runs_from: training` the design grows by itself
    (`design.base_shots`): only its training chunks run (the default, its own runs: tests/test_new_shots.py)."""
    results, config = study
    quick = load_config(REPO / "config" / "config.yaml")
    shot = dict(quick["shots"]["106S"], target_mm=4.0, velocity_input="V4", shear_modulus_inputs=["G1", "Delta4"])
    more = overlay(tmp_path / "shot.yaml", inputs={"V4": quick["inputs"]["V3"], "Delta4": quick["inputs"]["Delta3"]},
                   shots={"107S": shot}, observed={"records": {"107S": _own_record(quick, tmp_path)}},
                   design={"new_shots": {"runs_from": "training"}})
    jobs = pending_jobs(config, more)
    assert jobs["simulate"] == jobs["features_chunk"] == 4 and jobs["features"] == 1, jobs   # 107S's 4 chunks


def test_bad_config_is_rejected_before_any_job(tmp_path):
    bad = overlay(tmp_path / "bad.yaml", simulate={"chunk_size": 0})
    done = snakemake("all", "--dry-run", config_files=[bad], check=False)
    assert done.returncode != 0
    assert "simulate.chunk_size" in done.stdout + done.stderr


def comparable_tables(results: Path) -> dict[str, pd.DataFrame]:
    """Every Parquet and CSV table of a results directory by relative path, without wall times."""
    tables = {}
    for path in sorted(results.rglob("*")):
        if path.suffix in (".parquet", ".csv") and "benchmarks" not in path.parts:
            table = pd.read_parquet(path) if path.suffix == ".parquet" else pd.read_csv(path)
            tables[path.relative_to(results).as_posix()] = table.drop(columns=["wall_time_s"], errors="ignore")
    return tables


@pytest.mark.slow   # a second quick study, about 3 min
def test_two_clean_runs_give_identical_tables_and_emulator(study, tmp_path):
    results, _ = study
    again = tmp_path / "results"
    snakemake("all", "--cores", "2", config_files=[overlay(tmp_path / "again.yaml", study={"results_dir": str(again)})])
    ours, theirs = comparable_tables(again), comparable_tables(results)
    assert ours.keys() == theirs.keys() and len(ours) > 30, sorted(set(ours) ^ set(theirs))
    for name, table in ours.items():
        pd.testing.assert_frame_equal(table, theirs[name], check_exact=True, obj=name)
    assert (again / "emulator" / "emulator.json").read_text() == (results / "emulator" / "emulator.json").read_text()
    with np.load(again / "emulator" / "emulator.npz") as a, np.load(results / "emulator" / "emulator.npz") as b:
        assert a.files == b.files and all(np.array_equal(a[k], b[k]) for k in a.files)


def finished_outputs(log: str) -> set[str]:
    """Output files of the jobs snakemake reported finished in its log."""
    outputs, finished, current = {}, set(), []
    for line in log.splitlines():
        line = line.strip()
        if line.startswith("output: "):
            current = line.removeprefix("output: ").split(", ")
        elif line.startswith("jobid: "):
            outputs[line.removeprefix("jobid: ")] = current
        elif line.startswith("Finished jobid: "):
            finished.update(outputs.get(line.split()[2], []))
    return finished


@pytest.mark.slow   # 30-40 s; the stale lock of kill -9 is checked in the fast suite
def test_a_second_snakemake_on_the_directory_is_refused(tmp_path):
    """While a study runs, a second snakemake on the same directory stops at the lock, and the first
    is not disturbed."""
    config = overlay(tmp_path / "locked.yaml", study={"results_dir": str(tmp_path / "results")})
    first = snakemake("all", "--cores", "1", config_files=[config], start_new_session=True)
    deadline = time.monotonic() + 120
    while not list((tmp_path / "results").glob("training/simulations/*/chunk-*.parquet")) and time.monotonic() < deadline:
        time.sleep(0.1)
    try:
        second = snakemake("all", "--cores", "1", config_files=[config], check=False)
        assert first.poll() is None, "the first run ended before the second started: no lock to test"
        assert second.returncode != 0 and "cannot be locked" in second.stdout + second.stderr, second.stdout[-2000:]
    finally:
        os.killpg(first.pid, signal.SIGKILL)
        first.communicate(timeout=60)
        snakemake("--unlock", config_files=[config])


@pytest.mark.slow   # 27-35 s for kill -9 (2026-11-28): `make test-slow` keeps make test under 8 minutes
@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGKILL], ids=["ctrl-c", "kill-9"])
def test_interrupted_fan_out_finishes_with_identical_results(study, tmp_path, sig):
    """Ctrl-C or kill -9 in the middle of the fan-out; the rerun (after `--unlock` when kill -9 left
    the lock behind) recomputes no chunk snakemake reported finished, and gives the same tables as
    the uninterrupted study."""
    results, _ = study
    resumed = tmp_path / "results"
    config = overlay(tmp_path / "resumed.yaml", study={"results_dir": str(resumed)})
    target = resumed / "training" / "features" / "104S.parquet"
    chunks = resumed / "training" / "simulations" / "104S"
    run = snakemake(str(target), "--cores", "1", config_files=[config], start_new_session=True)
    deadline = time.monotonic() + 120
    while not any(chunks.glob("chunk-*.parquet")) and time.monotonic() < deadline and run.poll() is None:
        time.sleep(0.1)                                         # the first chunk done, whichever snakemake ran first
    os.killpg(run.pid, sig)                                     # in the middle of the fan-out
    log, _ = run.communicate(timeout=120)
    written = sorted(p.name for p in chunks.glob("chunk-*.parquet"))
    assert 1 <= len(written) < 4 and not target.exists(), written
    # a chunk written in the instant before kill -9 may not be recorded as finished: it reruns
    finished = {p.name: p.stat().st_mtime_ns for p in chunks.glob("chunk-*.parquet") if str(p) in finished_outputs(log)}

    if sig == signal.SIGKILL:                                   # snakemake had no chance to release its lock
        refused = snakemake(str(target), "--cores", "2", config_files=[config], check=False)
        assert refused.returncode != 0 and "--unlock" in refused.stdout + refused.stderr
        snakemake("--unlock", config_files=[config])
    snakemake(str(target), "--cores", "2", config_files=[config])
    assert {name: (chunks / name).stat().st_mtime_ns for name in finished} == finished, "a finished chunk was rerun"
    assert not list(chunks.glob(".*tmp*")), "temporaries left behind"
    for k in range(4):
        ours = pd.read_parquet(chunks / f"chunk-{k}.parquet").drop(columns="wall_time_s")
        reference = pd.read_parquet(results / "training" / "simulations" / "104S" / f"chunk-{k}.parquet").drop(columns="wall_time_s")
        pd.testing.assert_frame_equal(ours, reference, check_exact=True)
    pd.testing.assert_frame_equal(pd.read_parquet(target), pd.read_parquet(results / "training" / "features" / "104S.parquet"),
                                  check_exact=True)


def test_make_quick_names_its_target_before_the_configfile():
    """`make quick`'s snakemake line parses: a target after --configfile would be read as a config file."""
    lines = subprocess.run(["make", "-n", "quick"], cwd=REPO, capture_output=True, text=True, check=True).stdout
    command = next(line.split() for line in lines.splitlines() if line.startswith("snakemake "))
    done = subprocess.run([SNAKEMAKE, "--dry-run", *command[1:]], cwd=REPO, capture_output=True, text=True)
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]


def make_lines(*args: str) -> list[str]:
    """The lines `make -n ARGS` prints (the environment's install step taken as done)."""
    return subprocess.run(["make", "-n", "-o", ".venv/.installed", *args], cwd=REPO, capture_output=True, text=True,
                          check=True).stdout.splitlines()


def test_make_study_runs_the_waves_and_make_paper_the_papers_design():
    """The default study is the sequential one (config/sequential.yaml over the paper's config, results/sequential);
    `make paper`, or STUDY=paper for study, check and next-shot, runs the paper's design into results; another
    STUDY is refused in one line before anything runs."""
    runs = [line for line in make_lines("study") if line.startswith("snakemake ")]
    assert runs[0].endswith("--cores all all --configfile config/sequential.yaml") and "results/sequential/" in runs[0]
    paper = [line for line in make_lines("study", "STUDY=paper") if line.startswith("snakemake ")]
    assert paper[0].split()[-2:] == ["all", "all"] and "--logger-shockcal-log-dir results/logs/" in paper[0]
    assert "make --no-print-directory study STUDY=paper" in make_lines("paper")
    for target, rule in (("check", "check"), ("next-shot", "next_shot"), ("next-shot-check", "next_shot_check")):
        assert any(line.endswith(f" {rule} --configfile config/sequential.yaml") for line in make_lines(target)), target
        assert any(line.rstrip().endswith(f" {rule}") and "results/logs/" in line
                   for line in make_lines(target, "STUDY=paper")), target
    done = subprocess.run(["make", "-n", "study", "STUDY=lhs"], cwd=REPO, capture_output=True, text=True)
    assert done.returncode != 0 and done.stderr.strip().endswith("STUDY=lhs: sequential (the default) or paper.  Stop.")
    dry = subprocess.run([SNAKEMAKE, "--dry-run", *runs[0].split()[1:]], cwd=REPO, capture_output=True, text=True)
    assert dry.returncode == 0 and "rule wave_design:" in dry.stdout, dry.stdout[-2000:] + dry.stderr[-2000:]


def test_the_next_shot_check_without_a_ranking_stops_with_one_line(tmp_path):
    """`snakemake next_shot_check` compares the ranking's best and worst: with no ranking.csv it stops before any job."""
    fresh = overlay(tmp_path / "fresh.yaml", study={"results_dir": str(tmp_path / "results")})
    done = snakemake("next_shot_check", "--dry-run", config_files=[fresh], check=False)
    errors = [line for line in (done.stdout + done.stderr).splitlines() if line.startswith("shockcal: error:")]
    assert done.returncode != 0 and len(errors) == 1 and "ranking.csv: missing" in errors[0], done.stderr[-2000:]
    assert "Traceback" not in done.stdout + done.stderr


@pytest.mark.slow   # the last of this module's tests: its outputs would join the seed and noise tests' params checks
def test_next_shot_check_target_on_the_quick_study(study, tmp_path):
    """`snakemake next_shot_check` on the quick study (quick.yaml: 3 truths, 20 training runs per candidate): both
    candidates as fourth shots, their runs at the first 20 training rows and at the truths (the three shots'
    training runs reused, not rerun), the per-truth table and the summary with its verdicts; `all` untouched."""
    results, config = study
    snakemake("next_shot", "--cores", "2", config_files=[config], read_log=tmp_path)
    ranking = pd.read_csv(results / "next_shot" / "ranking.csv")
    snakemake("next_shot_check", "--cores", "2", config_files=[config], read_log=tmp_path)
    check = pd.read_csv(results / "next_shot" / "check.csv")
    assert set(check["candidate"]) == set(ranking["candidate"]) and check["run"].nunique() == 3
    sds = [f"{k}sd_{p}" for k in ("", "baseline_") for p in ("A", "B", "C", "n", "m")]
    assert np.isfinite(check["gain_nats"]).all() and (check[sds] > 0).all().all()
    summary = pd.read_csv(results / "next_shot" / "check_summary.csv")
    best, worst = ranking["candidate"].iloc[0], ranking["candidate"].iloc[-1]
    difference = summary[summary["row"] == f"{best} - {worst}"]
    assert set(difference["quantity"]) == {"gain_nats", *(f"ln_sd_{p}" for p in ("A", "B", "C", "n", "m"))}
    assert set(difference["verdict"]) <= {"holds", "does not hold"} and (difference["n_truths"] == 3).all()
    gain = summary.set_index(["row", "quantity"]).loc[(best, "gain_nats")]
    assert gain["predicted"] == pytest.approx(ranking["eig_nats"].iloc[0], rel=1e-5)
    for name in (best, worst):                                  # 20 runs in 2 chunks of 10; the truths in 1
        assert len(pd.read_parquet(results / "next_shot_check" / "features" / f"{name}.parquet")) == 20
        assert len(list((results / "next_shot_check" / "simulations" / name).glob("chunk-*.parquet"))) == 2
    assert not (results / "next_shot_check" / "simulations" / "104S").exists()
    assert pending_jobs(config) == {} and pending_jobs(config, target="next_shot_check") == {}
    unread, stages = unread_keys(tmp_path)              # every key the next-shot stages declare is read
    unread = {stage: [key for key in keys if not key.startswith(NOT_READ_HERE.get(stage, ()))]
              for stage, keys in unread.items()}
    assert not any(unread.values()), f"declared and never read (stage: keys): {unread}"
    assert {"next_shot_design", "next_shot_simulate", "next_shot_features", "suggest_shot", "next_shot_check_truths",
            "calibrate_check", "next_shot_check_summary"} <= stages, stages
