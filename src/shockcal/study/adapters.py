"""The study config turned into the library's typed settings: one adapter per setting, in one place.

Each adapter takes a validated config (or the slice its stage reads, `shockcal.study.stages`) and
returns what a library function takes; the library never sees a dict. Field names of the settings
are the config's keys, so most adapters copy by name. The emulator's and the calibration's modules are
imported by their adapters, so that a simulate job does not pay for them (0.7 s a job); the settings
models of the emulator, the extractor and the calibration are light modules of their own.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from shockcal.design.tables import InputBox, ShotMapping, extend_design, latin_hypercube, load_design
from shockcal.emulator.settings import EmulatorSettings
from shockcal.hydro import Geometry, HydroSettings, MaterialProperties
from shockcal.hydro.material_library import material_properties as library_material_properties
from shockcal.inference.settings import CalibrationSettings, SamplerSettings
from shockcal.seeds import stream_seed
from shockcal.study.config import (
    AUTO_END_MARGIN_US,
    PER_RUN_RISE_FRACTION,
    candidate_config,
    end_time_us,
    input_user_units,
    prior_bounds,
    shot_config,
    velocity_box_m_s,
    wave_sizes,
)
from shockcal.study.strength_config import material_constants, strength_law, strength_parameters
from shockcal.velocimetry.settings import ExtractorSettings

if TYPE_CHECKING:
    import pandas as pd

    from shockcal.campaign.candidates import Candidate
    from shockcal.emulator.study_emulator import EmulatorSpec


def input_box(config: dict) -> InputBox:
    """The prior box (`inputs`), the shots' velocity inputs (for messages) and `checks.design_box`."""
    return InputBox(prior_bounds(config), {name: box["unit"] for name, box in config["inputs"].items()},
                    {spec["velocity_input"]: shot for shot, spec in config["shots"].items()},
                    config["checks"]["design_box"])


def shot_mapping(config: dict, shot: str) -> ShotMapping:
    """How `shot` reads a design row (`shots.<shot>`, `strength.model` and the law's boxed parameters in
    `inputs`; a ConfigError names an unknown shot)."""
    spec = shot_config(config, shot)
    law = strength_law(config)
    modulus = () if law.shear_modulus is not None else tuple(spec["shear_modulus_inputs"])
    return ShotMapping(shot, spec["velocity_input"], modulus, law.name, tuple(strength_parameters(config)))


def material_properties(config: dict) -> MaterialProperties:
    """`material` (a library name, overrides, either EOS form: `shockcal.hydro.material_library.material_properties`)."""
    return library_material_properties(config["material"])


def hydro_settings(config: dict) -> HydroSettings:
    """`hydro` (its `end_time_us` belongs to the geometry)."""
    return HydroSettings(**{name: config["hydro"][name] for name in HydroSettings.model_fields})


def hydro_inputs(config: dict, spec: dict, end_us: float | None = None
                 ) -> tuple[Geometry, MaterialProperties, HydroSettings]:
    """`run_shot`'s inputs for a shot besides its parameters: (Geometry, MaterialProperties,
    HydroSettings). `spec` is the shot's config section (`shot_config(config, shot)`); `end_us` (us)
    defaults to the config's end time (`end_time_us`; with `per_run` each run also ends the analysis window
    plus AUTO_END_MARGIN_US after its free surface's rise); the shot's `initial_temperature_K` (K), left out, is
    the material's T_ref_K."""
    per_run = end_us is None and config["hydro"]["end_time_us"] == "per_run"
    end_us = end_time_us(config, spec) if end_us is None else end_us
    stop = {"stop_after_rise_us": float(spec["analysis"]["window_after_arrival_us"]) + AUTO_END_MARGIN_US,
            "rise_fraction": PER_RUN_RISE_FRACTION} if per_run else {}
    return (Geometry.from_section(spec, end_us=float(end_us), **stop), material_properties(config),
            hydro_settings(config))


def extractor_settings(config: dict, shot: str) -> ExtractorSettings:
    """`shots.<shot>.analysis` and `features`."""
    return ExtractorSettings(**shot_config(config, shot)["analysis"], **config["features"])


def candidate_extractor_settings(config: dict, name: str) -> ExtractorSettings:
    """A next-shot candidate's analysis window (`candidate_config`) and `features`."""
    return ExtractorSettings(**candidate_config(config, name)["analysis"], **config["features"])


def candidate(config: dict, name: str) -> Candidate:
    """`next_shot.candidates.<name>` with its reference shot's shear-modulus inputs and the study's law and
    its inputs."""
    from shockcal.campaign.candidates import Candidate
    from shockcal.campaign.settings import CandidateShot

    spec = candidate_config(config, name)
    return Candidate(name=name, **{key: spec[key] for key in CandidateShot.model_fields},
                     shear_modulus_inputs=tuple(spec["shear_modulus_inputs"]), model=strength_law(config).name,
                     strength_inputs=tuple(strength_parameters(config)))


def candidate_box(config: dict, name: str) -> InputBox:
    """The box a candidate's design lies in: the prior box of the law's inputs (`strength_parameters`), and the
    candidate's velocity (cm/us, within the velocity error's range) and shear modulus (Mbar, the
    reference shot's box plus the range of its thermal increment, `shear_modulus_increment_box_Mbar`:
    it holds both the ranking's draws, G_ref (1 + s dT), and the next-shot check's training runs, whose
    increment is an input of its own)."""
    from shockcal.campaign.candidates import SHEAR_MODULUS, VELOCITY
    from shockcal.study.config import shear_modulus_box_Mbar, shear_modulus_increment_box_Mbar
    from shockcal.units import CM_US_TO_M_S

    shot = candidate(config, name)
    section = config["next_shot"]
    spread = 3.0**0.5 * section["velocity_sd_fraction"]
    velocity = shot.velocity_m_s / CM_US_TO_M_S
    g_box = shear_modulus_box_Mbar(config, config["next_shot"]["candidates"][name]["shot"]) or (0.0, float("inf"))
    increment = shear_modulus_increment_box_Mbar(config, name) or (0.0, 0.0)
    strength = strength_parameters(config)
    bounds = {**{k: v for k, v in prior_bounds(config).items() if k in strength},
              VELOCITY: (velocity * (1 - spread), velocity * (1 + spread)),
              SHEAR_MODULUS: (g_box[0] + increment[0], g_box[1] + increment[1])}
    units = {**{k: config["inputs"][k]["unit"] for k in strength}, VELOCITY: "cm/us", SHEAR_MODULUS: "Mbar"}
    return InputBox(bounds, units, {VELOCITY: name}, config["checks"]["design_box"])


def emulator_settings(config: dict) -> EmulatorSettings:
    """`emulator` (the GP settings by name), seeded by study.seed."""
    return EmulatorSettings.from_section(config["emulator"], seed=config["study"]["seed"])


def emulator_spec(config: dict, shots) -> EmulatorSpec:
    """`emulator`, `inputs`, the shots' mappings and study.seed, for the emulator of `shots` (the power
    inputs eps^n and T*^m for a law whose declaration gives both roles, `Law.role_column`: Johnson-Cook's n
    and m; the yield input for the laws of `emulator.yield_input`,
    at material.T_ref_K with the law's material constants)."""
    from shockcal.emulator.input_map import POWER_INPUTS
    from shockcal.emulator.study_emulator import EmulatorSpec
    from shockcal.emulator.yield_input import YieldInput

    section = config["emulator"]
    law = strength_law(config)
    model = law.name
    exponents = [(key, law.role_column(role)) for key, role in POWER_INPUTS]
    powers = tuple((section[key], column) for key, column in exponents
                   if section[key] and all(column for _, column in exponents))
    mappings = {s: shot_mapping(config, s) for s in shots}
    yield_section = section.get("yield_input")    # left out of the stage's slice for a law it does not list
    yield_input = None
    if yield_section is not None and model in yield_section["models"]:
        columns = tuple(strength_parameters(config))
        yield_input = YieldInput(model, columns, yield_section["strain_rate_per_s"], config["material"]["T_ref_K"],
                                 material_constants(config, model, columns))
    return EmulatorSpec(section["structure"], mappings, prior_bounds(config), powers, emulator_settings(config),
                        yield_input=yield_input)


def sampler_settings(config: dict, seed: int, check: bool = False) -> SamplerSettings:
    """`calibration`'s sampler keys by name, seeded by `seed`; with `check`, a synthetic-truth trial's: n_live and
    n_eff of `calibration.check`, as many draws as n_eff, one run (`calibration.cube_power` and `max_evaluations`
    for both)."""
    section = config["calibration"]
    if not check:
        return SamplerSettings.from_section(section, seed=seed)
    trial = section["check"]
    return SamplerSettings(n_live=trial["n_live"], n_eff=trial["n_eff"], draws=trial["n_eff"], seed=seed,
                           cube_power=section["cube_power"], max_evaluations=section["max_evaluations"])


def calibration_settings(config: dict, shots, check: bool = False) -> CalibrationSettings:
    """`calibration` (`sampler_settings`: with `check`, the synthetic-truth trials' `calibration.check`),
    `observed.sd_fraction`, `checks.observed_units`, the
    prior box `inputs` and their units, the shots' impact-velocity boxes for the plateau check
    (`checks.plateau_vs_velocity`; not for the check's synthetic measurements), the training-range check
    (`checks.features_in_training_range`; the check's synthetic measurements only warn), seeded by the shots'
    "calibration" stream of study.seed (a trial reseeds from its own); the summary's user units
    (`input_user_units`)."""
    sampler = sampler_settings(config, stream_seed(config["study"]["seed"], "calibration", *shots), check)
    boxes = {} if check else {shot: velocity_box_m_s(config, shot) for shot in shots if shot in config["shots"]}
    return CalibrationSettings(sampler=sampler, sd_fraction=config["observed"]["sd_fraction"],
                               check_units=config["checks"]["observed_units"],
                               units={name: box["unit"] for name, box in config["inputs"].items()},
                               user_units=input_user_units(config), bounds=prior_bounds(config),
                               velocity_boxes={shot: box for shot, box in boxes.items() if box is not None},
                               check_plateau=config["checks"]["plateau_vs_velocity"],
                               check_training_range=config["checks"]["features_in_training_range"] and not check,
                               discrepancy=config["calibration"]["discrepancy"])


def load_study_design(path, config: dict, columns: list[str] | None = None, allow_empty: bool = False
                      ) -> pd.DataFrame:
    """`load_design` against the config's prior box (`input_box`); with `allow_empty`, no rows is fine."""
    return load_design(path, input_box(config), columns, allow_empty)


def base_inputs(config: dict) -> list[str]:
    """The inputs the design's Latin hypercube spans, in config order: those of `design.base_shots`
    (every shot when null). An input only a later shot reads gets a column of its own (`study_design`)."""
    return inputs_read_by(config, config["design"]["base_shots"] or list(config["shots"]))


def inputs_read_by(config: dict, shots) -> list[str]:
    """The design columns `shots` read, in config order."""
    used = {name for shot in shots for name in shot_mapping(config, shot).inputs()}
    return [name for name in config["inputs"] if name in used]


def new_posterior_shots(config: dict) -> list[str]:
    """The shots outside `design.base_shots` whose runs come from the base shots' joint posterior
    (`design.new_shots.runs_from: posterior`), in config order; none when base_shots is null."""
    base = config["design"]["base_shots"]
    if not base or config["design"]["new_shots"]["runs_from"] != "posterior":
        return []
    return [shot for shot in config["shots"] if shot not in base]


def base_study_config(config: dict) -> dict:
    """The study as its base shots (`design.base_shots`) alone make it (`study_of_shots`). The base
    shots' emulator and joint posterior, which place a new shot's runs, are computed under it, so adding a
    shot changes none of their settings."""
    return study_of_shots(config, config["design"]["base_shots"] or list(config["shots"]))


def new_shot_config(config: dict, shot: str) -> dict:
    """The base study with the new shot `shot` back in: what that shot's design and runs read, so that
    adding another shot reruns neither."""
    return study_of_shots(config, [*(config["design"]["base_shots"] or []), shot])


def study_of_shots(config: dict, shots) -> dict:
    """`config` with only `shots`: the other shots, their records and published features, the inputs
    only they read and the next-shot candidates referring to them left out."""
    import copy

    kept = set(inputs_read_by(config, shots))
    study = copy.deepcopy(config)
    study["shots"] = {shot: spec for shot, spec in study["shots"].items() if shot in shots}
    study["inputs"] = {name: spec for name, spec in study["inputs"].items() if name in kept}
    for key in ("records", "features"):
        if isinstance(study["observed"].get(key), dict):
            study["observed"][key] = {shot: v for shot, v in study["observed"][key].items() if shot in shots}
    study["next_shot"]["candidates"] = {name: spec for name, spec in study["next_shot"]["candidates"].items()
                                        if spec.get("shot") in shots}
    return study


def extension_inputs(config: dict) -> dict[str, str]:
    """Input -> the first shot (config order) outside `design.base_shots` that reads it, for the inputs
    the base shots do not read: each gets its own column, seeded by that shot and its name."""
    base = set(base_inputs(config))
    owner: dict[str, str] = {}
    for shot in config["shots"]:
        for name in shot_mapping(config, shot).inputs():
            if name not in base:
                owner.setdefault(name, shot)
    return {name: owner[name] for name in config["inputs"] if name in owner}


def study_design(config: dict, n_runs: int | None = None, seed: int | None = None, stream: str = "design",
                 lhs: bool = False) -> tuple[pd.DataFrame, str]:
    """(design, where it came from): the archive's design rows that have runs (`simulator.kind: archive`),
    or the config's design file (its first `n_runs` rows), or, without one or with `lhs`, a Latin
    hypercube of `n_runs` (default design.n_runs; a sequential study's wave 0, design.waves.initial_runs)
    over the box of
    `base_inputs`, seeded from `stream` of study.seed (`shockcal.seeds`) unless `seed` is given.

    An input that only a shot outside `design.base_shots` reads (a shot added to a study: its own
    impact velocity or modulus increment), and that the design file does not hold, is drawn as a
    column of its own for the existing rows (`extend_design`, stream design_extension keyed by the
    shot and the input): no existing column changes, so no other shot's runs rerun."""
    from shockcal.io import read_table
    from shockcal.study.simulator import archive_design, simulator_kind

    names, extension = list(config["inputs"]), extension_inputs(config)
    if not lhs and simulator_kind(config) == "archive":
        design, source = archive_design(config, lambda path: load_study_design(path, config))
        design = design if n_runs is None else design.iloc[:n_runs]
    elif not lhs and config["design"]["file"]:
        path = config["design"]["file"]
        given = set(read_table(path).columns)
        design = load_study_design(path, config, [n for n in names if n not in extension or n in given])
        design, source = (design if n_runs is None else design.iloc[:n_runs]), f"file {path}"
    else:
        seed = stream_seed(config["study"]["seed"], stream) if seed is None else seed
        bounds = prior_bounds(config)
        design = latin_hypercube({n: bounds[n] for n in names if n not in extension}, n_runs or wave_sizes(config)[0],
                                 seed)
        source = f"Latin hypercube, seed {seed}"
    missing = {n: shot for n, shot in extension.items() if n not in design.columns}
    if missing:
        bounds = prior_bounds(config)
        design = extend_design(design, {n: bounds[n] for n in missing},
                               {n: stream_seed(config["study"]["seed"], "design_extension", shot, n)
                                for n, shot in missing.items()})
        source += f"; {', '.join(missing)} drawn for shot(s) {', '.join(dict.fromkeys(missing.values()))}"
    return design[["run", *names]], source


def observed_table(config: dict) -> pd.DataFrame:
    """The measured features of every shot (one row per shot: shot, source, the ten features, each
    calibration feature's read-out sd `readout_sd_v_*` in m/s and the record's noise model), from the
    VISAR records through the extractor (`observed.source: records`; the read-out sds from
    `observed.readout_replicates` noise replicates seeded by the shot's `readout` stream of study.seed
    when `observed.readout_error`, else 0) or the published values (read-out sds 0, no noise model); a
    plastic plateau that does not fit the shot's impact velocity (`checks.plateau_vs_velocity`) is an
    InputError naming the shot and the record."""
    import pandas as pd

    from shockcal.errors import ConfigError
    from shockcal.plausibility import check_plateau
    from shockcal.velocimetry.columns import COLUMNS, READOUT_COLUMNS, RECORD_NOISE_COLUMNS
    from shockcal.velocimetry.feature_tables import record_features

    observed = config["observed"]
    if observed["source"] == "synthetic":
        raise ConfigError("observed.source is 'synthetic': this study has no measured features")
    replicates = observed["readout_replicates"] if observed["readout_error"] else 0
    rows = []
    for shot in config["shots"]:      # the config's validation checked that every shot has its source's entry
        if observed["source"] == "records":
            spec = observed["records"][shot]
            where = f"record {spec['path']} (observed.records.{shot}.path)"
            rows.append({"shot": shot, "source": f"record {spec['path']} (shockcal extractor)",
                         **record_features(spec["path"], extractor_settings(config, shot), shot,
                                           spec["time_column"], spec["velocity_column"], replicates,
                                           stream_seed(config["study"]["seed"], "readout", shot))})
        else:
            where = f"observed.features.{shot}"
            rows.append({"shot": shot, "source": f"published ({where})",
                         **observed["features"][shot], **dict.fromkeys(READOUT_COLUMNS, 0.0),
                         "noise_sd_m_s": float("nan"), "noise_ar_order": 0, "readout_half_window_ns": 0.0})
        box = velocity_box_m_s(config, shot)
        if box is not None:        # a record of another shot: its plateau is another impact velocity's
            check_plateau(rows[-1], box, f"shot {shot}: {where}", config["checks"]["plateau_vs_velocity"])
    return pd.DataFrame(rows)[["shot", "source", *COLUMNS, *READOUT_COLUMNS, *RECORD_NOISE_COLUMNS]]


def command_settings(config: dict):
    """`simulator.command` as `CommandSettings` (its output as `OutputSpec`)."""
    from shockcal.simulators.command import CommandSettings
    from shockcal.simulators.outputs import OutputSpec

    section = config["simulator"]["command"]
    return CommandSettings.from_section(section, output=OutputSpec(**section["output"]))


def archive_source(config: dict, shot: str):
    """`simulator.archive` for `shot`: its features table's path, or its traces pattern with their `OutputSpec`
    (`ArchiveSource`), paths resolved (`shockcal.study.simulator.resolve_path`)."""
    from shockcal.errors import ConfigError
    from shockcal.simulators.archive import ArchiveSource
    from shockcal.simulators.outputs import OutputSpec
    from shockcal.study.simulator import resolve_path

    section = config["simulator"]["archive"]
    design = resolve_path(section["design"], "simulator.archive.design", section)
    if shot in section.get("features", {}):
        return ArchiveSource(design, features=resolve_path(section["features"][shot], f"simulator.archive.features.{shot}",
                                                           section))
    if shot not in section.get("traces", {}):
        raise ConfigError(f"simulator.archive: no runs of {shot} (neither features.{shot} nor traces.{shot}); an archive "
                          "holds the training runs of the study's shots only")
    pattern = section["traces"][shot]
    resolved = resolve_path(pattern, f"simulator.archive.traces.{shot}", section)
    return ArchiveSource(design, traces=str(resolved), trace=OutputSpec(**{**section.get("trace", {}), "kind": "trace",
                                                                            "file": Path(pattern).name}))
