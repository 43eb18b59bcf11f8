"""A finished study's results, read back in one call: `load_study(results_dir)`.

It reads what the workflow wrote under a study's results directory (`study.results_dir`: `results/`
for config/config.yaml, `results/quick/` for config/quick.yaml), not its config:

- `posterior/{shot,...,joint}.parquet` with their weighted draws: one `Posterior` per calibration
  (`shockcal.inference.posterior_files.read_posterior`; `summary()` in MPa, GPa and m/s);
- `posterior/{name}.nc`: the same posteriors as ArviZ InferenceData (`shockcal posterior-netcdf`; the
  inputs named with their user units, `A_MPa`, `G1_GPa`, `V1_m_s`);
- `emulator/`: the study's emulator (`shockcal.emulator.study_emulator.Emulator.load`);
- `features/observed.parquet`: the measured features per shot (times in us, velocities in m/s).

A directory that lacks any of them is refused in one line naming what is missing.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from shockcal.emulator.study_emulator import Emulator
from shockcal.errors import InputError
from shockcal.inference.posterior_files import read_posterior
from shockcal.inference.sampler import Posterior
from shockcal.io import read_table, read_table_metadata

JOINT = "joint"


@dataclass
class StudyResults:
    """A finished study's posteriors (`Posterior` and InferenceData by calibration: each shot, then
    "joint"), its emulator and its measured features (`observed`: one row per shot)."""

    results_dir: Path
    shots: list[str]
    posteriors: dict[str, Posterior]
    inference_data: dict
    emulator: Emulator
    observed: pd.DataFrame

    def __repr__(self) -> str:
        runs = "; ".join(f"{len(block.runs)} training runs of {'+'.join(block.shots)}" for block in self.emulator.blocks)
        lines = [f"StudyResults({str(self.results_dir)!r}): shots {', '.join(self.shots)}",
                 f"  emulator ({self.emulator.structure}): {runs}; {len(self.emulator.feature_names)} features per shot "
                 f"({', '.join(self.emulator.feature_names)}, m/s)",
                 f"  observed: {len(self.observed)} shots' measured features (features/observed.parquet)",
                 f"  {'posterior':<10} {'draws':>6} {'weighted':>9} {'Kish ESS':>9}  log Z"]
        for name, posterior in self.posteriors.items():
            lines.append(f"  {name:<10} {len(posterior.draws):>6} {len(posterior.weighted.points):>9} "
                         f"{posterior.weighted.kish_ess():>9.0f}  {posterior.log_evidence:.3f} "
                         f"+- {posterior.log_evidence_sd:.3f}")
        lines.append("  .posteriors[name].summary() (MPa, GPa, m/s), .inference_data[name] (ArviZ), .emulator, "
                     ".observed")
        return "\n".join(lines)


def load_study(results_dir) -> StudyResults:
    """The posteriors (as `Posterior` and as ArviZ InferenceData), the emulator and the measured features
    of the finished study in `results_dir` (module docstring); InputError in one line naming what is
    missing when it is not a finished study."""
    import arviz as az

    root = Path(results_dir)
    if not root.is_dir():
        raise InputError(f"{root}: no such directory (a study's results directory, e.g. results/quick after "
                         "`make quick`)")
    joint = root / "posterior" / f"{JOINT}.parquet"
    shots = list(read_table_metadata(joint).get("shots") or []) if joint.is_file() else []
    names = [*shots, JOINT]
    needed = [joint, root / "emulator" / "emulator.json", root / "emulator" / "emulator.npz",
              root / "features" / "observed.parquet",
              *(root / "posterior" / f"{name}{suffix}" for name in names for suffix in ("_weighted.parquet", ".nc")),
              *(root / "posterior" / f"{shot}.parquet" for shot in shots)]
    missing = [str(path.relative_to(root)) for path in dict.fromkeys(needed) if not path.is_file()]
    if missing:
        below = [str(d) for d in sorted(root.iterdir()) if (d / "posterior" / f"{JOINT}.parquet").is_file()]
        hint = f"; studies below it: {', '.join(below)}" if below else ""
        raise InputError(f"{root}: not a finished study ({', '.join(missing)} missing; run the workflow into it, "
                         f"e.g. `make quick` for results/quick){hint}")
    observed = read_table(root / "features" / "observed.parquet")
    return StudyResults(root, shots, {name: read_posterior(root / "posterior" / f"{name}.parquet") for name in names},
                        {name: az.from_netcdf(root / "posterior" / f"{name}.nc") for name in names},
                        Emulator.load(root / "emulator"), observed)
