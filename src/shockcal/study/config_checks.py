"""The study config's rules beyond what the JSON schema can say: the settings models' own (`check_model_sections`),
and across keys: boxes ordered, shot mappings and sampler powers naming real inputs, plates, windows and
velocities consistent with the material and the hydrocode's physical rules (`shockcal.hydro.rules`), the waves'
and the next-shot study's settings, the design file. `shockcal.study.validate.validate_config` runs them after
the schema, in that order; each refusal is one line naming the key.
"""

from __future__ import annotations

from pathlib import Path

from shockcal.errors import ConfigError, InputError, number
from shockcal.hydro import rules
from shockcal.plausibility import check_observed, check_plateau, release_times_us
from shockcal.settings_model import KEY, SettingsError, schema_extras
from shockcal.study.adapters import study_design
from shockcal.study.config import candidate_config, shear_modulus_box_Mbar, velocity_box_m_s
from shockcal.study.config_files import MODEL_SECTIONS
from shockcal.study.strength_config import next_shot_targets, strength_law
from shockcal.units import MM_TO_CM


def check_model_sections(config: dict, source: str = "config") -> None:
    """Each section that is a settings model's (`MODEL_SECTIONS`) through its model: the rules the schema cannot
    say (`calibration.replicates` 2) in the model's words, naming the key. A section given as a word (a
    discrepancy `none`) has none to check."""
    for section, model in MODEL_SECTIONS.items():
        for where, values in _sections(config, section.split(".")):
            if isinstance(values, dict):
                _section_model(model, values, where, source)


def _sections(node, keys: list[str], where: str = ""):
    """(key path, values) of each config section a dotted path names (`*`: every key of a mapping; `shots.*`:
    each shot's), none where the config lacks the key."""
    if not keys:
        yield where.removeprefix("."), node
        return
    if not isinstance(node, dict):
        return
    for key in (node if keys[0] == "*" else [keys[0]] if keys[0] in node else []):
        yield from _sections(node[key], keys[1:], f"{where}.{key}")


def _section_model(model, values: dict, section: str, source: str):
    """`model` of the config `section`'s `values`, with a key of the section that is another model's (the
    command's `output`) built first, so a problem names the key it is in; a SettingsError as a ConfigError."""
    nested = {}
    for name, extra in schema_extras(model).items():
        where = extra.get(KEY, "")                  # simulator.command.output: a key of this section
        if where.startswith(f"{section}.") and isinstance(values.get(key := where.removeprefix(f"{section}.")), dict):
            nested[name] = _section_model(model.model_fields[name].annotation, values[key], where, source)
    try:
        return model.from_section(values, **nested)
    except SettingsError as exc:
        raise ConfigError(f"{source}: {section}.{exc.field}: {exc.reason}") from None


def check_semantics(config: dict, source: str = "config") -> None:
    """Rules beyond the schema: box bounds ordered, shot mappings and sampler powers name real inputs, files
    exist, observed features look like m/s and us (shockcal.plausibility)."""
    inputs = config["inputs"]     # each box's min below its max: InputRange (check_model_sections)
    law = strength_law(config)
    required = tuple(law.calibrated_columns()) if law.code_unit_columns else ()    # a box given in `inputs`
    who = law.title.split(" (")[0]
    for name in required:
        if name not in inputs:
            raise ConfigError(f"{source}: inputs.{name}: missing; the {who} inputs {required} are required")
        problem = rules.problem(inputs[name]["min"], "nonnegative")       # ShotParameters' rule
        if problem:
            raise ConfigError(f"{source}: inputs.{name}.min: {problem}; {who} parameters cannot be negative")
    for shot, spec in config["shots"].items():
        mapped = [("velocity_input", spec["velocity_input"])]
        mapped += [(f"shear_modulus_inputs[{i}]", name) for i, name in enumerate(spec["shear_modulus_inputs"])
                   if not _law_has_modulus(config)]
        for key, name in mapped:
            if name not in inputs:
                raise ConfigError(f"{source}: shots.{shot}.{key}: '{name}' is not one of the inputs {sorted(inputs)}")
    for shot, spec in config["shots"].items():
        check_initial_temperature(spec, config["material"], f"{source}: shots.{shot}.initial_temperature_K")
        check_plates(spec, config["hydro"]["cell_size_um"], f"{source}: shots.{shot}")
        check_velocity_box(config, shot, source)
    for name in config["calibration"]["cube_power"]:
        if name not in inputs:
            raise ConfigError(f"{source}: calibration.cube_power.{name}: not one of the inputs {sorted(inputs)}")
    for shot in config["design"]["base_shots"] or []:
        if shot not in config["shots"]:
            raise ConfigError(f"{source}: design.base_shots: '{shot}' is not a shot; known shots are {sorted(config['shots'])}")
    check_waves(config, source)
    design_file = config["design"].get("file")
    if design_file and not Path(design_file).is_file():
        raise ConfigError(f"{source}: design.file: {design_file} does not exist")
    observed = config["observed"]
    for section in ("features", "records"):
        for shot in observed[section]:
            if shot not in config["shots"]:
                raise ConfigError(f"{source}: observed.{section}.{shot}: unknown shot; known shots are {sorted(config['shots'])}")
    for shot, features in observed["features"].items():
        check_observed(features, f"{source}: observed.features.{shot}", config["checks"]["observed_units"], ConfigError)
    check_distinct(observed, source)
    for shot, features in observed["features"].items():
        box = velocity_box_m_s(config, shot)
        if box is not None:
            check_plateau(features, box, f"{source}: observed.features.{shot}",
                          config["checks"]["plateau_vs_velocity"], ConfigError)
    for shot, record in observed["records"].items():
        if not Path(record["path"]).is_file():
            raise ConfigError(f"{source}: observed.records.{shot}.path: {record['path']} does not exist")
    for shot in config["shots"]:
        check_window(config, shot, source)
    check_next_shot(config, source)
    source_section = "records" if observed["source"] == "records" else "features"
    for shot in config["shots"] if observed["source"] != "synthetic" else []:
        if shot not in observed[source_section]:
            raise ConfigError(f"{source}: observed.{source_section}.{shot}: missing, and observed.source is "
                              f"{observed['source']!r}; give it, or set observed.source to "
                              f"{'published' if source_section == 'records' else 'records'}")


def check_waves(config: dict, source: str = "config") -> None:
    """A sequential study's wave 0 is a Latin hypercube (no `design.file`) and its runs are made, not looked up
    (no `simulator.kind: archive`); `WaveSettings` checks that its budget holds wave 0."""
    if config["design"]["strategy"] != "waves":
        return
    if config["design"]["file"]:
        raise ConfigError(f"{source}: design.file: a design file and design.strategy: waves do not go together "
                          "(wave 0 is a Latin hypercube); set one of them")
    if (config.get("simulator") or {}).get("kind") == "archive":
        raise ConfigError(f"{source}: simulator.kind: an archive holds only the runs it has, and design.strategy: "
                          "waves places new ones; use design.strategy: lhs with an archive")


def _law_has_modulus(config: dict) -> bool:
    """Whether the study's law computes G itself (then the shots' shear-modulus inputs are not read)."""
    return strength_law(config).shear_modulus is not None


# the plastic rise needs this long inside the window after the plastic wave arrives (the paper's shots rise
# from 10% to 90% of it, t_slope1 to t_slope2, in 0.06-0.16 us)
PLASTIC_RISE_US = 0.2


def expand_candidate_grid(config: dict, source: str = "config") -> None:
    """`next_shot.grid` added to `next_shot.candidates`, one named candidate per combination (null
    candidates read as none; the grid's reference shot, left out, is the study's first); a grid name that is
    already another candidate is a ConfigError."""
    section = config.get("next_shot") or {}
    if section.get("candidates", {}) is None:
        section["candidates"] = {}
    grid = section.get("grid")
    if not grid:
        return
    import itertools

    if grid.get("shot") is None and config.get("shots"):
        grid["shot"] = next(iter(config["shots"]))          # the study's first shot
    for flyer, target, velocity, temperature in itertools.product(grid["flyer_mm"], grid["target_mm"],
                                                                  grid["velocity_m_s"], grid["initial_temperature_K"]):
        name = f"{grid['shot']}-{flyer:g}x{target:g}mm-{velocity:g}ms-{temperature:g}K"
        spec = {"shot": grid["shot"], "flyer_mm": flyer, "target_mm": target, "velocity_m_s": velocity,
                "initial_temperature_K": temperature}
        if section["candidates"].get(name, spec) != spec:   # the same entry: a config validated before
            raise ConfigError(f"{source}: next_shot.grid: candidate {name} is also in next_shot.candidates")
        section["candidates"][name] = spec


def check_next_shot(config: dict, source: str = "config") -> None:
    """The next-shot section: targets among the inputs, each candidate's reference shot known, its name
    not a shot's, its initial temperature below melting, its window clear of the release (plates too
    thin for it) and long enough for the plastic wave to arrive and rise (`PLASTIC_RISE_US`). The split
    of the elastic and plastic waves needs the posterior (`shockcal.campaign.candidates.check_split`)."""
    section, inputs = config["next_shot"], config["inputs"]
    targets = next_shot_targets(config)
    for target in targets:
        if target not in inputs:
            raise ConfigError(f"{source}: next_shot.targets: unknown target '{target}'; the inputs are {sorted(inputs)}")
    for name in section["check"]["candidates"] or []:
        if name not in section["candidates"]:
            raise ConfigError(f"{source}: next_shot.check.candidates: unknown candidate '{name}'; next_shot.candidates "
                              f"are {sorted(section['candidates'])}")
    for name, spec in section["candidates"].items():
        where = f"{source}: next_shot.candidates.{name}"
        if name in config["shots"]:
            raise ConfigError(f"{where}: '{name}' is also a shot's name; give the candidate its own")
        if spec["shot"] not in config["shots"]:
            raise ConfigError(f"{where}.shot: '{spec['shot']}' is not a shot; known shots are {sorted(config['shots'])}")
        check_initial_temperature(spec, config["material"], f"{where}.initial_temperature_K")
        check_plates(spec, config["hydro"]["cell_size_um"], where)
        box = shear_modulus_box_Mbar(config, spec["shot"])
        if box is None:
            continue
        candidate = candidate_config(config, name)
        check_window_fits(config, candidate, box[1], where)
        material = config["material"]
        c_bulk = (material["eos"]["c1_Mbar"] / material["rho0_g_cc"]) ** 0.5
        c_l = (c_bulk**2 + 4.0 * box[1] / (3.0 * material["rho0_g_cc"])) ** 0.5
        lag = spec["target_mm"] * MM_TO_CM * (1.0 / c_bulk - 1.0 / c_l)
        window = candidate["analysis"]["window_after_arrival_us"]
        if window < lag + PLASTIC_RISE_US:
            raise ConfigError(
                f"{where}: the plastic wave reaches the free surface {lag:.3g} us after the elastic precursor (target "
                f"{spec['target_mm']:g} mm), and the analysis window ({window:.3g} us, ended by the release from the "
                f"{spec['flyer_mm']:g} mm flyer) leaves under {PLASTIC_RISE_US:g} us for its rise: the plates are too "
                "thin for a plateau; take a thicker flyer or a thinner target")


def check_initial_temperature(spec: dict, material: dict, where: str) -> None:
    """A shot's initial temperature (K) must lie below the material's melting temperature: the
    Johnson-Cook strength vanishes at T* = 1 and the plates would start molten."""
    temperature = spec.get("initial_temperature_K")
    if temperature is not None and not temperature < material["T_melt_K"]:
        raise ConfigError(f"{where}: {temperature:g} K is at or above material.T_melt_K ({material['T_melt_K']:g} K); "
                          "a shot starts solid, below the melting temperature")


def check_plates(spec: dict, cell_size_um: float, where: str) -> None:
    """Each plate of a shot or candidate section `spec` at least one cell thick, the hydrocode's own rule
    (`shockcal.hydro.rules.plate_problem`, which `HydroSettings.cells` applies)."""
    for plate in ("flyer_mm", "target_mm"):
        problem = rules.plate_problem(spec[plate], cell_size_um)
        if problem:
            raise ConfigError(f"{where}.{plate}: {problem}")


def check_velocity_box(config: dict, shot: str, source: str) -> None:
    """Both ends of `shot`'s impact-velocity box (its `velocity_input`, in a velocity unit shockcal knows)
    obey the hydrocode's impact-velocity rule (`ShotParameters.velocity_m_s`)."""
    box = velocity_box_m_s(config, shot)
    name = config["shots"][shot]["velocity_input"]
    for end, value_m_s in zip(("min", "max"), box or (), strict=True):
        problem = rules.problem(value_m_s, "impact_velocity_m_s")
        if problem:
            raise ConfigError(f"{source}: inputs.{name}.{end}: {number(config['inputs'][name][end])} "
                              f"{config['inputs'][name]['unit']}, shot {shot}'s impact velocity in m/s: {problem}")


def check_distinct(observed: dict, source: str) -> None:
    """Two shots with the same record file, or the same measured features, are a copy-paste slip (a
    shot's own measurement would be calibrated against another's): a ConfigError naming both."""
    seen: dict = {}
    for shot, record in observed["records"].items():
        key = Path(record["path"]).resolve()
        if key in seen:
            raise ConfigError(f"{source}: observed.records.{shot}.path: {record['path']} is also the record of shot "
                              f"{seen[key]} (observed.records.{seen[key]}.path); each shot has its own record")
        seen[key] = shot
    seen = {}
    for shot, features in observed["features"].items():
        key = tuple(sorted(features.items()))
        if key in seen:
            raise ConfigError(f"{source}: observed.features.{shot}: the same values as observed.features.{seen[key]}; "
                              "each shot has its own measurement")
        seen[key] = shot


def check_window(config: dict, shot: str, source: str) -> None:
    """The analysis window of `shot` must end before the release from the flyer's back reaches the free
    surface (`shockcal.plausibility.release_times_us`, with the config's material and plates, and the
    largest shear modulus of the shot's prior box: the earliest release); a window reaching it would
    read the release as part of the plateau. Shear-modulus inputs in a unit other than
    SHEAR_MODULUS_TO_MBAR's are not checked. A law with its own G law (SG, PTW) uses its G0_GPa box's
    maximum: the rise of G with pressure is left out, so this check is a little lenient for them."""
    box = shear_modulus_box_Mbar(config, shot)
    if box is not None:
        check_window_fits(config, config["shots"][shot], box[1], f"{source}: shots.{shot}")


def check_window_fits(config: dict, spec: dict, g_max_Mbar: float, where: str) -> None:
    """`check_window` for a shot section `spec` (a shot's or a candidate's, `candidate_config`) and the
    largest shear modulus `g_max_Mbar`; `where` names its config key."""
    material = config["material"]
    arrival, release = release_times_us(spec["flyer_mm"], spec["target_mm"], material["rho0_g_cc"],
                                        material["eos"]["c1_Mbar"], g_max_Mbar)
    window = spec["analysis"]["window_after_arrival_us"]
    if window >= release - arrival:
        raise ConfigError(
            f"{where}.analysis.window_after_arrival_us: {window:g} us reaches the release from the "
            f"flyer's back, {release - arrival:.3g} us after the first arrival (first arrival {arrival:.3g} us after "
            f"impact, release {release:.3g} us: flyer {spec['flyer_mm']:g} mm, target {spec['target_mm']:g} mm, "
            f"the box's largest shear modulus {g_max_Mbar * 100:.3g} GPa); end the window before it")


def check_design_file(config: dict, source: str = "config") -> None:
    """The config's design file (`design.file`), if any, read and checked as every stage will read it
    (finite, inside the prior box, ...; `study_design`: an input only a shot outside design.base_shots
    reads may be missing, it is drawn), so that a bad file stops the config's load with its row."""
    design_file = config["design"].get("file")
    if not design_file:
        return
    try:
        study_design(config)
    except InputError as exc:
        raise ConfigError(f"{source}: design.file: {exc}") from None
