"""The paper's fifteen figures, and the study's own after them, by file name: what each reads and which
function draws it.

Importing this module is cheap (the Snakefile lists the figures from it); plotting modules are
imported when a figure is built. It lives in the study package, beside the other config readers: the
plotting modules (`shockcal.plots`) import nothing of the study package.

Inputs arrive as named files (`FigureInputs`): keys `<kind>` or `<kind>:<shot or calibration>`
with the kinds of `INPUT_KINDS` (`observed`, `posterior:joint`, `features:104S`, ...); a key may
name several files (simulation chunks), which are concatenated. A key that was not given reads as
None and the figure shows a "no data" note; a given file that is missing or unreadable is an
InputError. Each entry says which keys it `needs` for the config's shots, and the workflow
(workflow/rules/figures.smk) maps every kind to the files that make it: adding a figure is one entry here.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass
from functools import partial
from typing import TYPE_CHECKING

from shockcal.errors import InputError
from shockcal.seeds import stream_seed

if TYPE_CHECKING:
    import pandas as pd


# what each input kind is (the workflow's figures.smk maps every kind to its files)
log = logging.getLogger(__name__)
INPUT_KINDS = {
    "observed": "the observed features (features/observed.parquet)",
    "cv": "the emulator's cross-validation table (emulator/cv.parquet)",
    "emulator_predictions": "emulator predictions at the posterior-predictive design",
    "record": "a shot's measured VISAR record (observed.records.<shot>.path)",
    "sample_simulations": "a sample of a shot's training runs: its first simulation chunk",
    "simulations": "every training run of a shot (all simulation chunks)",
    "predicted_simulations": "a shot's hydrocode runs at posterior draws (run set 'predict')",
    "features": "a shot's training features",
    "predicted_features": "the features of a shot's runs at posterior draws",
    "posterior": "a calibration's posterior draws (a shot or 'joint')",
    "sobol": "the emulator's Sobol indices (sensitivity/sobol.csv)",
    "next_shot_ranking": "the next-shot candidates' ranking (next_shot/ranking.csv)",
}


class FigureInputs:
    """Named input files of one figure, read on demand."""

    def __init__(self, files: dict[str, list[str]] | None = None):
        self.files = dict(files or {})

    def table(self, key: str) -> pd.DataFrame | None:
        """The table(s) under `key`, concatenated; None when the key was not given."""
        import pandas as pd

        from shockcal.io import read_table

        paths = self.files.get(key)
        if not paths:
            return None
        tables = [read_table(p) for p in paths]
        return tables[0] if len(tables) == 1 else pd.concat(tables, ignore_index=True)

    def per(self, kind: str, names) -> dict[str, pd.DataFrame | None]:
        """{name: table of `kind:name`} for each name."""
        return {name: self.table(f"{kind}:{name}") for name in names}

    def record(self, shot: str, config: dict) -> pd.DataFrame | None:
        """The measured record of `shot` (t_us, v_m_s), read with the project's record reader and the
        columns named in observed.records.<shot> (if any)."""
        paths = self.files.get(f"record:{shot}")
        if not paths:
            return None
        import pandas as pd

        from shockcal.velocimetry.records import read_record

        spec = config["observed"]["records"].get(shot, {})
        t, v = read_record(paths[0], spec.get("time_column"), spec.get("velocity_column"))
        return pd.DataFrame({"t_us": t, "v_m_s": v})


@dataclass(frozen=True)
class FigureSpec:
    name: str
    category: str
    build: Callable  # (FigureInputs, config) -> matplotlib Figure
    reads: tuple[str, ...] = ()  # config keys `build` reads besides `figures` (shockcal.study.stages paths)
    needs: tuple[str, ...] = ()  # FigureInputs keys `build` reads, for the config's shots (kinds: INPUT_KINDS)
    target: str = "all"  # the workflow target that makes it (`all`, or `next_shot`: outside the study)


def _shots(config) -> list[str]:
    """The shots by name: the order every job's config has (the workflow writes it with sorted keys), whatever
    order snakemake's config merge gave the Snakefile (a shot added by an overlay came first there)."""
    return sorted(config["shots"])


def _toy(name, inputs, config):
    from shockcal.plots import toys

    return getattr(toys, name)()


def _records(inputs, config):
    from shockcal.plots.records import fig02_records

    shots = _shots(config)
    return fig02_records({s: inputs.record(s, config) for s in shots}, inputs.table("observed"), shots)


def _trace_figure(which, inputs, config):
    from shockcal.plots import mixture
    from shockcal.study.adapters import extractor_settings

    shot = _shots(config)[0]
    trace, label = mixture.pick_trace(inputs.record(shot, config), inputs.table(f"sample_simulations:{shot}"), shot)
    return getattr(mixture, which)(trace, label, extractor_settings(config, shot))


def _crossval(inputs, config):
    from shockcal.plots.crossval import fig06_crossval

    return fig06_crossval(inputs.table("cv"), _shots(config))


def _references(config):
    """The study's reference sets to draw (`study.reference_sets` of its law); a value outside the prior box
    is drawn and logged, not refused."""
    from shockcal.study.references import drawn_sets, outside_box

    for line in outside_box(config):
        log.warning(line)
    return drawn_sets(config)


def _marginals(inputs, config):
    from shockcal.plots.posterior import fig07_marginals

    return fig07_marginals(inputs.per("posterior", [*_shots(config), "joint"]), config, _references(config))


def _pairs(inputs, config):
    from shockcal.plots.posterior import fig08_pairs

    return fig08_pairs(inputs.table("posterior:joint"), config, references=_references(config))


def _features_emulator(inputs, config):
    from shockcal.plots.feature_space import feature_space

    shots = _shots(config)
    predictions = inputs.table("emulator_predictions")
    predicted = {s: None if predictions is None else predictions[predictions["shot"].astype(str) == s] for s in shots}
    return feature_space(inputs.per("features", shots), predicted, inputs.table("observed"), shots,
                         config["observed"]["sd_fraction"], "emulator")


def _features_hydrocode(inputs, config):
    from shockcal.plots.feature_space import feature_space

    shots = _shots(config)
    return feature_space(inputs.per("features", shots), inputs.per("predicted_features", shots),
                         inputs.table("observed"), shots, config["observed"]["sd_fraction"], "hydrocode")


def _history(shot, inputs, config):
    from shockcal.plots.feature_space import observed_row
    from shockcal.plots.histories import estimate_time_shift, fig_history

    measured = observed_row(inputs.table("observed"), shot)
    aligned_to = inputs.table(f"predicted_features:{shot}")
    if aligned_to is None:
        aligned_to = inputs.table(f"features:{shot}")
    return fig_history(shot, inputs.table(f"simulations:{shot}"), inputs.table(f"predicted_simulations:{shot}"),
                       measured, inputs.record(shot, config), estimate_time_shift(measured, aligned_to),
                       seed=stream_seed(config["study"]["seed"], "figures"))


def _measured_against_training(inputs, config):
    from shockcal.plots.training_range import measured_against_training

    shots = _shots(config)
    return measured_against_training(inputs.per("features", shots), inputs.table("observed"), shots,
                                     config["observed"]["sd_fraction"])


def _sobol(inputs, config):
    from shockcal.plots.sensitivity import sobol_indices

    return sobol_indices(inputs.table("sobol"), _shots(config))


def _next_shot(inputs, config):
    from shockcal.plots.next_shot import next_shot_ranking
    from shockcal.study.strength_config import next_shot_targets

    return next_shot_ranking(inputs.table("next_shot_ranking"), next_shot_targets(config))


def history_names(config) -> dict[str, str]:
    """{figure name: shot} for Figs 11-13 (the first three shots by name)."""
    return {f"fig{11 + i}_history_{shot}": shot for i, shot in enumerate(_shots(config)[:3])}


# what the builders read: the shots (names, analysis windows), the records' columns, the extractor's
# settings, the prior box and the reference sets of its law, the observation error, the figures' random stream
_SHOT_NAMES = ("shots.{names}",)
_POSTERIOR = ("shots.*.shear_modulus_inputs", "inputs", "strength.model?", "study.reference_sets?")
_FEATURE_SPACE = (*_SHOT_NAMES, "observed.sd_fraction")


def _record_columns(shot: str) -> tuple[str, ...]:
    """A shot's record's columns (the record itself is the figure's input file), when the shot has one."""
    return tuple(f"observed.records.{shot}.{column}?" for column in ("time_column", "velocity_column"))


def catalogue(config) -> dict[str, FigureSpec]:
    """Every figure of the study: the paper's, in its order, then the study's own (cheap: nothing is imported
    until a figure is built)."""
    shots = _shots(config)
    recorded = [s for s in shots if s in config.get("observed", {}).get("records", {})]

    def per(kind, names):
        return tuple(f"{kind}:{name}" for name in names)

    # Figs 4, 5, 15 draw one trace: the first shot's record when configured, else one of its runs
    trace = per("record" if shots[0] in recorded else "sample_simulations", shots[:1])
    trace_reads = (*_SHOT_NAMES, f"shots.{shots[0]}.analysis", *_record_columns(shots[0]), "features")
    features = per("features", shots)

    def history(shot):
        runs = ("simulations", "predicted_simulations", "features", "predicted_features")
        return ("observed", *(f"{kind}:{shot}" for kind in runs), *per("record", [shot] if shot in recorded else []))

    specs = [
        FigureSpec("fig01_toy_calibration", "1 method", partial(_toy, "fig01_toy_calibration")),
        FigureSpec("fig02_records", "2 data", _records, (*_SHOT_NAMES, *(c for s in recorded for c in _record_columns(s))),
                   ("observed", *per("record", recorded))),
        FigureSpec("fig03_gp_draws", "1 method", partial(_toy, "fig03_gp_draws")),
        FigureSpec("fig04_trace_features", "2 data", partial(_trace_figure, "fig04_trace_features"), trace_reads, trace),
        FigureSpec("fig05_mixture_split", "1 method", partial(_trace_figure, "fig05_mixture_split"), trace_reads, trace),
        FigureSpec("fig06_crossval", "3 emulator", _crossval, _SHOT_NAMES, ("cv",)),
        FigureSpec("fig07_marginals", "4 posterior", _marginals, _POSTERIOR, per("posterior", [*shots, "joint"])),
        FigureSpec("fig08_pairs", "4 posterior", _pairs, _POSTERIOR, ("posterior:joint",)),
        FigureSpec("fig09_features_emulator", "5 posterior predictions", _features_emulator, _FEATURE_SPACE,
                   (*features, "observed", "emulator_predictions")),
        FigureSpec("fig10_features_hydrocode", "5 posterior predictions", _features_hydrocode, _FEATURE_SPACE,
                   (*features, "observed", *per("predicted_features", shots))),
        *(FigureSpec(name, "5 posterior predictions", partial(_history, shot),
                     (*_record_columns(shot), "study.seed"),
                     history(shot))
          for name, shot in history_names(config).items()),
        FigureSpec("fig14_inadequate_model", "1 method", partial(_toy, "fig14_inadequate_model")),
        FigureSpec("fig15_pit_construction", "1 method", partial(_trace_figure, "fig15_pit_construction"), trace_reads,
                   trace),
        # beyond the paper
        FigureSpec("sobol_indices", "6 sensitivity", _sobol, _SHOT_NAMES, ("sobol",)),
        FigureSpec("features_vs_training", "2 data", _measured_against_training, _FEATURE_SPACE,
                   (*features, "observed")),
        # which shot next (`make next-shot`), when the config has candidates
        *([FigureSpec("next_shot", "7 next shot", _next_shot, ("next_shot.targets", "strength.model?", "inputs.{names}"),
                      ("next_shot_ranking",), "next_shot")] if config.get("next_shot", {}).get("candidates") else []),
    ]
    return {spec.name: spec for spec in specs}


def figure_spec(name: str, config: dict) -> FigureSpec:
    """The catalogue entry of figure `name`; an unknown name is an InputError listing the known ones."""
    specs = catalogue(config)
    if name not in specs:
        raise InputError(f"unknown figure '{name}'; known figures: {', '.join(specs)}")
    return specs[name]


def build_figure(name: str, inputs: FigureInputs, config: dict):
    """Draw figure `name` (config: at least the keys its spec `reads`); an unknown name is an
    InputError listing the known ones."""
    return figure_spec(name, config).build(inputs, config)
