"""The next-shot check's studies (docs/next_shot.md, "The realized check"): which candidates it compares,
and each as the fourth shot of a study derived from the config, added the way a shot is added by config
alone (docs/workflow.md, "How to add a shot").

A candidate `<c>` becomes shot `<c>` with its plates, initial temperature and analysis window
(`candidate_config`) and two inputs of its own, drawn as new columns of the training design:
`V_<c>` (cm/us), its impact velocity, uniform over the candidate's velocity times 1 +- sqrt(3) x
next_shot.velocity_sd_fraction (the ranking's velocity factor), and, for a candidate whose
temperature is not the reference one, `dG_<c>` (Mbar), its shear modulus's increment over the
reference shot's, uniform over the range of G_ref s (T0 - T_ref) for G_ref in the reference shot's box
and s in next_shot.shear_modulus_log_slope_per_K. A candidate at the reference temperature reads the
reference shot's modulus inputs as they are (the ranking's model: the same G).
"""

from __future__ import annotations

import copy
from pathlib import Path

from shockcal.errors import ConfigError, InputError
from shockcal.study.config import candidate_config, shear_modulus_increment_box_Mbar
from shockcal.units import CM_US_TO_M_S


def check_inputs(config: dict, name: str) -> tuple[str, str | None]:
    """(velocity input, shear-modulus increment input or None) of candidate `name` as a fourth shot."""
    spec = candidate_config(config, name)
    heated = spec["initial_temperature_K"] not in (None, config["material"]["T_ref_K"])
    return f"V_{name}", (f"dG_{name}" if heated else None)


def derived_study_config(config: dict, name: str, design_file: str | Path) -> dict:
    """The study config with candidate `name` added as a fourth shot (module docstring), its training design
    the study's (`design_file`, the new inputs drawn as columns of their own), no measurements
    (observed.source synthetic) and no next-shot candidates; validated."""
    from shockcal.study.validate import validate_config

    spec, section = candidate_config(config, name), config["next_shot"]
    velocity_input, increment_input = check_inputs(config, name)
    derived = copy.deepcopy(config)
    spread = 3.0**0.5 * section["velocity_sd_fraction"]
    velocity = spec["velocity_m_s"] / CM_US_TO_M_S
    derived["inputs"][velocity_input] = {"min": velocity * (1 - spread), "max": velocity * (1 + spread), "unit": "cm/us"}
    modulus = list(spec["shear_modulus_inputs"])
    if increment_input is not None:
        box = shear_modulus_increment_box_Mbar(config, name)
        if box is None:
            raise ConfigError(f"next_shot.check: candidate {name}: its reference shot's shear modulus is not in Mbar, "
                              "GPa or kbar; its increment's box cannot be set")
        derived["inputs"][increment_input] = {"min": box[0], "max": box[1], "unit": "Mbar"}
        modulus.append(increment_input)
    shot = {"flyer_mm": spec["flyer_mm"], "target_mm": spec["target_mm"], "velocity_input": velocity_input,
            "shear_modulus_inputs": modulus, "analysis": spec["analysis"]}
    if spec["initial_temperature_K"] is not None:
        shot["initial_temperature_K"] = spec["initial_temperature_K"]
    # its training design is the file (a sequential study's: wave 0, its Latin hypercube), so the derived study
    # is a Latin-hypercube one whatever the study's strategy
    derived["design"] = {**config["design"], "strategy": "lhs", "file": str(design_file),
                         "base_shots": config["design"]["base_shots"] or list(config["shots"])}
    derived["shots"][name] = shot
    derived["observed"] = {**config["observed"], "source": "synthetic"}
    derived["next_shot"] = {"candidates": None, "targets": section["targets"]}
    return validate_config(derived, f"next_shot.check: the study with candidate {name} added")


def check_candidates(config: dict, ranking_path: str | Path) -> list[str]:
    """The candidates the check compares: next_shot.check.candidates, or the best and the worst of the ranking
    by eig_nats. An InputError names a missing or unreadable ranking, or one without two candidates of the
    config's next_shot.candidates."""
    given = config["next_shot"]["check"]["candidates"]
    if given is not None:
        return list(given)
    import pandas as pd

    path = Path(ranking_path)
    if not path.is_file():
        raise InputError(f"{path}: missing: the check compares the ranking's best and worst candidates; run `make "
                         "next-shot` first, or name two in next_shot.check.candidates")
    try:
        ranking = pd.read_csv(path)
    except (ValueError, OSError) as exc:
        raise InputError(f"{path}: not a readable CSV: {exc}") from None
    if not {"candidate", "eig_nats"} <= set(ranking.columns):
        raise InputError(f"{path}: no candidate and eig_nats columns: not a ranking of `shockcal suggest-shot`")
    ranking = ranking[ranking["candidate"].astype(str).isin(config["next_shot"]["candidates"])]
    if len(ranking) < 2:
        raise InputError(f"{path}: fewer than two candidates of next_shot.candidates; rerun `make next-shot`")
    ranking = ranking.sort_values("eig_nats", ascending=False, kind="stable")
    return [str(ranking["candidate"].iloc[0]), str(ranking["candidate"].iloc[-1])]


def plan_check(config: dict, ranking_path: str | Path, design_file: str | Path, directory: str | Path,
               required: bool) -> dict[str, dict]:
    """The check's derived studies, for the workflow when it is read (as the training design is): candidate ->
    `config` (the derived config's path), `design` (its training design's path), `study` (the derived config),
    `table` (the training design, with the candidate's velocity and shear modulus in the columns its runs read
    as a next-shot candidate's, `Candidate.mapping`: they go through the run sets' rules as the ranking's do),
    each file under `directory`/<candidate>/ written when its content changes. A check that cannot be planned
    (no ranking yet, or next_shot.check's settings do not fit the study) gives {} unless `required` (the check
    is asked for), when the error goes up: a study is never refused for a check it was not asked to run."""
    try:
        return derived_studies(config, check_candidates(config, ranking_path), design_file, directory)
    except (InputError, ConfigError):
        if required:
            raise
        return {}


def derived_studies(config: dict, names: list[str], design_file: str | Path, directory: str | Path
                    ) -> dict[str, dict]:
    """`plan_check`'s plans of candidates `names`, their files written; a ConfigError when the training design
    (`design_file`) has fewer rows than next_shot.check.n_training_runs."""
    from dataclasses import replace

    import yaml

    from shockcal.campaign.candidates import SHEAR_MODULUS, VELOCITY
    from shockcal.design.tables import write_design
    from shockcal.study.adapters import candidate_box, input_box, shot_mapping, study_design
    from shockcal.study.workflow import write_if_changed

    plans = {}
    for name in names:
        study = derived_study_config(config, name, design_file)
        design, source = study_design(study)
        n_runs = config["next_shot"]["check"]["n_training_runs"]
        if n_runs > len(design):
            raise ConfigError(f"next_shot.check.n_training_runs: {n_runs} is more than the training design's "
                              f"{len(design)} rows")
        velocity_input, _ = check_inputs(config, name)
        mapping = shot_mapping(study, name)
        design[VELOCITY] = design[velocity_input]
        design[SHEAR_MODULUS] = design[list(mapping.shear_modulus_inputs)].sum(axis=1)
        box = input_box(study)
        box = replace(box, bounds={**box.bounds, **{k: candidate_box(config, name).bounds[k] for k in (VELOCITY, SHEAR_MODULUS)}},
                      units={**box.units, VELOCITY: "cm/us", SHEAR_MODULUS: "Mbar"})
        folder = Path(directory) / name
        plans[name] = {"config": str(folder / "config.yaml"), "design": str(folder / "design.parquet"), "study": study,
                       "table": design}
        write_if_changed(plans[name]["config"], yaml.safe_dump(study, sort_keys=True))
        write_design(design, source, box, plans[name]["design"])
    return plans
