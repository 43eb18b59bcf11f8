"""The config keys each stage reads, declared once.

`STAGE_KEYS[stage]` lists dotted key paths of the validated study config. The same declaration
serves both channels a stage gets its settings through:

- the workflow's rules put `stage_config(config, stage, shot)` in their `params:`, so a change of
  any key the stage reads, and of no other, reruns it;
- `shockcal` commands call `load_stage_config`, which validates the whole config and hands the
  stage's library code only that slice, so code that reads an undeclared key fails at once (in
  the tests) instead of silently missing from the rerun triggers.

Path segments: a key; `*` every key at that level (e.g. every shot); `{shot}` the shot the job
works on; `{shot_inputs}` the design columns that shot reads (`ShotMapping.inputs`); `{names}`, last,
the names of the section's keys alone (`shots.{names}`: which shots, each an empty section, for a job
that reads no shot's settings). A trailing `?` marks an optional key, sliced only when the config gives
it: a key whose absence is its default (a shot's `initial_temperature_K`), so that declaring it reruns
none of the jobs of configs without it. A few keys depend on the config (`stage_config`): a law's
material constants, the observed stage's source, a candidate's reference shot, the waves' criterion.
"""
from __future__ import annotations

import copy
from collections.abc import Iterable, Iterator

from shockcal.design.settings import WaveSettings
from shockcal.hydro.settings import MaterialProperties, Plates
from shockcal.inference.settings import SamplerSettings
from shockcal.settings_model import KEY, OPTIONAL, SECTION, SettingsModel, schema_extras
from shockcal.study.adapters import shot_mapping
from shockcal.study.config import shot_config
from shockcal.study.read_log import recorded
from shockcal.study.strength_config import strength_law, strength_model
from shockcal.study.validate import load_config

NAMES = "{names}"


def model_keys(model: type[SettingsModel], section: str, optional: bool = True) -> tuple[str, ...]:
    """The config keys of `model`'s fields, in field order: `section.<field>`, or the section a field names
    (`setting(section=...)`: `material.eos`), once; an optional field's with `?` (sliced only when given), or
    none with `optional` false. A field the model gains is read, and reruns the stage, with no line here."""
    keys = []
    for name, extra in schema_extras(model).items():
        if KEY in extra or (extra.get(OPTIONAL) and not optional):
            continue
        key = f"{section}.{name}?" if extra.get(OPTIONAL) else extra.get(SECTION, f"{section}.{name}")
        keys += [key] if key not in keys else []
    return tuple(keys)


# a shot's plates (`Plates`) and how it reads a design row
_SHOT_GEOMETRY = (*model_keys(Plates, "shots.{shot}"), "shots.{shot}.velocity_input", "shots.{shot}.shear_modulus_inputs")
_SHOT_MAPPING = ("shots.*.velocity_input", "shots.*.shear_modulus_inputs", "strength.model?")

# the material's constants (`MaterialProperties`), not its library `name` (`shockcal.hydro.material_library`): a config
# naming its material and one giving the same values run the same jobs; the constants only some laws read (optional)
# are sliced for those laws only (`_law_material_keys`)
_MATERIAL = model_keys(MaterialProperties, "material", optional=False)

# what a next-shot candidate's section reads (`candidate_config`: its reference shot's plates, modulus and window,
# `_reference_shot_keys`; `adapters.candidate`: the study's law and its inputs)
_CANDIDATE = ("next_shot.candidates.{shot}", "inputs", "strength.model?", *_MATERIAL)
_REFERENCE_SHOT = ("flyer_mm", "target_mm", "shear_modulus_inputs", "analysis")
_CANDIDATE_SPREAD = ("next_shot.velocity_sd_fraction", "next_shot.shear_modulus_log_slope_per_K")
_CANDIDATE_STAGES = {"next_shot_design", "next_shot_simulate", "next_shot_features"}

# the sampler's keys, SamplerSettings' fields (`sampler_settings` reads them by name): a new field is read, and
# reruns the calibrations, with no line here
_SAMPLER = model_keys(SamplerSettings, "calibration")

STAGE_KEYS: dict[str, tuple[str, ...]] = {
    # the training design: a Latin hypercube of the box, or the design file checked against it
    "design": ("study.seed", "design", "inputs", "checks.design_box", "simulator.kind?", "simulator.archive?",
               *_SHOT_MAPPING),
    # the hypercube of the synthetic-truth check's hydrocode runs (--n-runs calibration.check.trials)
    "check_design": ("study.seed", "inputs", "calibration.check.trials", "design.base_shots", "checks.design_box",
                     *_SHOT_MAPPING),
    # one shot's hydrocode runs; the analysis window sets the simulated time when end_time_us is auto or per_run
    "simulate": (*_MATERIAL, "hydro", "checks.design_box", "inputs.{shot_inputs}", "strength.model?", "simulator?",
                 *_SHOT_GEOMETRY,
                 "shots.{shot}.analysis.window_after_arrival_us"),
    # features of one shot's traces (one chunk, or a whole run set with the failure budget)
    "features": ("features", "shots.{shot}.analysis"),
    # the failed-run budget where a shot's features are merged
    "failure_budget": ("simulate.max_failed_fraction", "shots.{shot}.analysis"),
    # the measured features of every shot (from the records or the published values)
    # (with the keys of its source, `_observed_keys`)
    "observed": ("observed.source", "checks.plateau_vs_velocity", "shots.*.velocity_input"),
    # the emulator fit and its cross-validation
    "emulate": ("study.seed", "emulator", "inputs", "checks.design_box", "material.T_ref_K", *_SHOT_MAPPING),
    # the emulator's predictions at a design's runs
    "emulate_predict": ("inputs", "checks.design_box", *_SHOT_MAPPING),
    # one calibration (single shot or joint)
    "calibrate": ("study.seed", *_SAMPLER, "calibration.discrepancy", "observed.sd_fraction", "checks.observed_units",
                  "checks.plateau_vs_velocity", "checks.features_in_training_range", "inputs", *_SHOT_MAPPING),
    # a batch of synthetic-truth trials
    # (calibration.check.trials_per_job plans the batches: the rule's --trial-range)
    "calibrate_check": ("study.seed", "calibration.check.trials", "calibration.check.n_live", "calibration.check.n_eff",
                        "calibration.cube_power", "calibration.max_evaluations",
                        "calibration.discrepancy", "observed.sd_fraction", "checks.observed_units",
                        "checks.plateau_vs_velocity",
                        "checks.features_in_training_range", "inputs", *_SHOT_MAPPING),
    # a sequential study's later wave (design.waves): the previous joint posterior thinned, the stopping rule
    # (and observed.sd_fraction for the max_variance criterion, `_max_variance`)
    "wave_design": ("study.seed", "design.strategy", *model_keys(WaveSettings, "design.waves"), "inputs",
                    "checks.design_box", *_SHOT_MAPPING),
    # a new shot's design (design.new_shots): the base shots' joint posterior thinned, its own inputs drawn
    "new_shot_design": ("study.seed", "design.base_shots", "design.new_shots", "design.waves.widen",
                        "design.waves.pool_size", "inputs", "checks.design_box", *_SHOT_MAPPING),
    # every run of a sequential study so far, one design and one features table per shot
    "merge_runs": ("inputs", "checks.design_box", *_SHOT_MAPPING),
    # joint-posterior draws as a design (`shockcal predict --stream`, one stage per stream): the predictive runs,
    # the posterior-truth check's truths, the hydrocode's verdict's draws (`make verify`)
    "predict": ("study.seed", "predict.n_posterior_runs", "inputs", "shots.{names}"),
    "check_posterior_design": ("study.seed", "calibration.check.trials", "inputs", "shots.{names}"),
    "verify_design": ("study.seed", "verify.n_draws", "inputs", "shots.{names}"),
    # the hydrocode's verdict: PSIS of the draws' hydrocode likelihood against the emulator's
    "verify": ("verify.n_draws", "calibration.discrepancy", "observed.sd_fraction", "inputs", "checks.design_box",
               *_SHOT_MAPPING),
    # Sobol indices of the emulator over the prior box and the joint posterior's 5-95% box
    "sensitivity": ("study.seed", "sensitivity", "inputs", "shots.*.shear_modulus_inputs"),
    # a next-shot candidate's design: the joint posterior's draws with the new shot's nuisance inputs
    "next_shot_design": ("study.seed", "next_shot.n_draws", "shots.{names}", *_CANDIDATE_SPREAD, *_CANDIDATE),
    # a candidate's hydrocode runs and their features
    "next_shot_simulate": ("hydro", "simulator?", "checks.design_box", *_CANDIDATE_SPREAD, *_CANDIDATE),
    "next_shot_features": ("features", *_CANDIDATE),
    # the candidates' information gains and their ranking
    "suggest_shot": ("study.seed", "next_shot.candidates", "next_shot.targets", "next_shot.emulator_error",
                     "next_shot.readout_sd_m_s", "observed.sd_fraction", "inputs.{names}", "material.T_ref_K",
                     "strength.model?"),
    # the next-shot check's truths: joint-posterior draws with each compared candidate's inputs
    "next_shot_check_truths": ("study.seed", "next_shot.candidates", "next_shot.check.n_truths",
                               *_CANDIDATE_SPREAD, "inputs", *_MATERIAL),
    # the next-shot check's realized gains and sds against the ranking
    "next_shot_check_summary": ("next_shot.targets", "inputs.{names}", "strength.model?"),
    # every figure; each adds the keys its catalogue entry `reads` (figure_config)
    "figures": ("figures",),
}


def stage_config(config: dict, stages: str | Iterable[str], shot: str | None = None) -> dict:
    """The slice of a validated `config` that `stages` read (a nested dict of the same shape),
    for `shot` where a path names `{shot}`."""
    stages = [stages] if isinstance(stages, str) else list(stages)
    unknown = [stage for stage in stages if stage not in STAGE_KEYS]
    if unknown:
        raise ValueError(f"unknown stage {unknown[0]!r}; stages: {', '.join(STAGE_KEYS)}")
    paths = [path for stage in stages for path in STAGE_KEYS[stage]] + _law_material_keys(config, stages)
    paths += _observed_keys(config) if "observed" in stages else []
    paths += _reference_shot_keys(config, stages, shot)
    paths += ["observed.sd_fraction"] if "wave_design" in stages and _max_variance(config) else []
    sliced = config_slice(config, paths, shot, "+".join(stages))
    if "emulate" in stages:
        _drop_unread_yield_input(config, stages, sliced)
    return sliced


def _law_material_keys(config: dict, stages: list[str]) -> list[str]:
    """The material keys that the study's law (other than Johnson-Cook, whose constants _MATERIAL holds) reads
    for the constants it does not calibrate (`shockcal.study.strength_config.material_constants`): in the slice
    of the simulate stage, and of the emulate stage for a law with the yield input; none for another law, so
    that a material key only PTW or Steinberg-Guinan reads reruns no other law's jobs."""
    law = strength_law(config)
    if law.code_unit_columns:     # Johnson-Cook: its constants are in _MATERIAL already
        return []
    yield_input = law.name in config["emulator"]["yield_input"]["models"]
    if "simulate" not in stages and not ("emulate" in stages and yield_input):
        return []
    return [f"material.{p.material}" for p in law.params
            if p.material is not None and p.name not in config["inputs"]]


# what the observed stage reads of its source (`observed.source`, `adapters.observed_table`): the records through
# the extractor with their read-out noise, or the published values
_OBSERVED_SOURCE = {"records": ("study.seed", "observed.records", "observed.readout_error", "observed.readout_replicates",
                                "features", "shots.*.analysis"),
                    "published": ("observed.features",)}


def _observed_keys(config: dict) -> list[str]:
    """The observed stage's keys that depend on the config: its source's (`_OBSERVED_SOURCE`), and the boxes of
    the shots' impact velocities, against which each plastic plateau is checked."""
    velocities = [f"inputs.{spec['velocity_input']}?" for spec in config["shots"].values()]
    return [*_OBSERVED_SOURCE.get(config["observed"]["source"], ()), *velocities]


def _reference_shot_keys(config: dict, stages: list[str], candidate: str | None) -> list[str]:
    """The keys of the reference shot (`next_shot.candidates.<name>.shot`) that a candidate's stages read of it
    (`_REFERENCE_SHOT`): the job's candidate's, or every candidate's for the next-shot check's truths."""
    candidates = config["next_shot"]["candidates"]
    names = [candidate] if candidate in candidates and set(stages) & _CANDIDATE_STAGES else []
    names += list(candidates) if "next_shot_check_truths" in stages else []
    shots = dict.fromkeys(candidates[name]["shot"] for name in names)
    return [f"shots.{shot}.{key}" for shot in shots for key in _REFERENCE_SHOT]


def _max_variance(config: dict) -> bool:
    """Whether the waves' criterion reads the observation error (the emulator's variance over it)."""
    return config["design"]["waves"]["criterion"] == "max_variance"


def documented_stage_keys() -> dict[str, tuple[str, ...]]:
    """`STAGE_KEYS` with the keys a stage reads under some config (the observed stage's sources, any input a shot's
    velocity may name): what docs/configuration.md's "reruns" column says."""
    sources = [key for keys in _OBSERVED_SOURCE.values() for key in keys]
    reference = tuple(f"shots.*.{key}" for key in _REFERENCE_SHOT)
    return {**STAGE_KEYS, "observed": (*STAGE_KEYS["observed"], *sources, "inputs"),
            "wave_design": (*STAGE_KEYS["wave_design"], "observed.sd_fraction"),
            **{stage: (*STAGE_KEYS[stage], *reference) for stage in (*_CANDIDATE_STAGES, "next_shot_check_truths")}}


def _drop_unread_yield_input(config: dict, stages: list[str], sliced: dict) -> None:
    """The emulate stage reads `emulator.yield_input` and material.T_ref_K only for a law in
    `emulator.yield_input.models` (`emulator_spec`): out of any other law's slice, so that adding or
    changing them reruns none of its jobs (material.T_ref_K stays where another stage declares it)."""
    if strength_model(config) in config["emulator"]["yield_input"]["models"]:
        return
    del sliced["emulator"]["yield_input"]
    others = [path for stage in stages if stage != "emulate" for path in STAGE_KEYS[stage]]
    if "material.T_ref_K" not in others:
        del sliced["material"]["T_ref_K"]
        if not sliced["material"]:
            del sliced["material"]


def figure_config(config: dict, name: str) -> dict:
    """The slice figure `name` reads: the figures stage's keys and its catalogue entry's `reads`."""
    from shockcal.study.figure_catalogue import figure_spec

    return config_slice(config, [*STAGE_KEYS["figures"], *figure_spec(name, config).reads], label=name)


def config_slice(config: dict, paths: Iterable[str], shot: str | None = None, label: str = "") -> dict:
    """The keys `paths` (this module's path syntax) of `config`, as a nested dict of the same shape;
    `label` names the declaration in errors."""
    sliced: dict = {}
    for path in paths:
        optional = path.endswith("?")
        parts = path.removesuffix("?").split(".")
        names = parts[-1] == NAMES
        for keys in _expand(config, parts[:-1] if names else parts, shot, label):
            if optional and not _present(config, keys):
                continue
            if names:
                _copy_names(config, keys, sliced, f"{label}: {path}")
            else:
                _copy(config, keys, sliced, f"{label}: {path}")
    return sliced


def load_stage_config(path, stages: str | Iterable[str], shot: str | None = None) -> dict:
    """Read and validate the whole study config at `path` (every key is checked), then return the
    slice `stages` read; with `shot`, an unknown shot is a ConfigError naming the known ones."""
    config = load_config(path)
    if shot is not None and shot not in config["next_shot"]["candidates"]:
        shot_config(config, shot)
    label = stages if isinstance(stages, str) else "+".join(stages)
    return recorded(stage_config(config, stages, shot), label)


def is_candidate(path, name: str) -> bool:
    """Whether `name` is a next-shot candidate of the study config at `path` (and not a shot): the
    `--shot` of `shockcal simulate` and `features` names either."""
    config = load_config(path)
    return name not in config["shots"] and name in config["next_shot"]["candidates"]


def _expand(config: dict, parts: list[str], shot: str | None, stage: str) -> Iterator[list[str]]:
    """Every concrete key path of one declared path."""
    for i, part in enumerate(parts):
        if part in ("{shot}", "{shot_inputs}") and shot is None:
            raise ValueError(f"stage {stage}: {'.'.join(parts)} needs a shot")
        if part == "{shot}":
            parts = [*parts[:i], shot, *parts[i + 1:]]
        elif part in ("*", "{shot_inputs}"):
            node = _node(config, parts[:i], f"{stage}: {'.'.join(parts)}")
            keys = node if part == "*" else shot_mapping(config, shot).inputs()
            for key in keys:
                yield from _expand(config, [*parts[:i], key, *parts[i + 1:]], shot, stage)
            return
    yield parts


def _node(config: dict, keys: list[str], declared: str):
    node = config
    for key in keys:
        if not isinstance(node, dict) or key not in node:
            raise KeyError(f"config key {'.'.join(keys)} (declared by stage {declared}) is not in the config")
        node = node[key]
    return node


def _present(config: dict, keys: list[str]) -> bool:
    """Whether the key path `keys` is in `config`."""
    node = config
    for key in keys:
        if not isinstance(node, dict) or key not in node:
            return False
        node = node[key]
    return True


def _copy_names(config: dict, keys: list[str], sliced: dict, declared: str) -> None:
    """The names of the section at `keys`, each an empty section unless a full path gave it."""
    target = sliced
    for key in keys:
        target = target.setdefault(key, {})
    for name in _node(config, keys, declared):
        target.setdefault(name, {})


def _copy(config: dict, keys: list[str], sliced: dict, declared: str) -> None:
    value = _node(config, keys, declared)
    target = sliced
    for key in keys[:-1]:
        target = target.setdefault(key, {})
    target[keys[-1]] = copy.deepcopy(value)  # a stage may change its slice (an option's override)
