"""A hydrocode change against another source tree (issue 62): printed, never asserted (docs/journal/hydro.md).

    python benchmarks/rate_return_compare.py --before ../main/src --rows 6 --inputs A C n V G1 [--mesh 8 4 2]
        [--flag 40] [--speed] [--model ptw]

Runs the same design rows of the paper's design (../shared/data/al5083/design.csv, Table IV units; with
`--model` another strength law, rows of a Latin hypercube of that law's box, seed 0: config/config.yaml with
`strength.model` set, the law's box from config/models.yaml; the MPa door and FLAG are Johnson-Cook's) twice,
once with each source tree (`--before`, e.g. a `git worktree` of main's src, and this tree's src), each in a
subprocess of its own (PYTHONPATH), and prints side by side:
  a. rounding floor: each input the shot reads raised by one part in 1e12 (`--inputs`), per feature the
     median and max |change| (m/s; times in ns);
  b. time step: CFL 0.25 against the config's 0.5, the max |change| per feature and the max |change| of
     the trace inside the analysis window (jump-off to `window_after_arrival_us` after it), everywhere and
     outside the fronts (where the base trace rises by less than FRONT_SLOPE: on a front a time shift of
     0.1 ns reads as m/s);
  c. the Mbar and MPa doors: `ShotParameters.from_table_iv` against the same values in MPa, GPa, m/s;
  d. speed: one 104S run at the nominal design row, CPU seconds (best of 3) and the load average;
  e. mesh (`--mesh`): v_elastic and the four calibration features at 8 / 4 / 2 um;
  f. against FLAG (`--flag N`): RMS of ours - FLAG over design runs 0..N-1 per shot, the same runs both ways.
One CPU-heavy process at a time (the two trees run one after the other).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd

ROOT = Path(__file__).resolve().parents[1]
CONFIG = ROOT / "config" / "config.yaml"
from shockcal.reference import reference_dir  # noqa: E402

DESIGN = (reference_dir() or ROOT.parents[1] / "shared" / "data" / "al5083") / "design.csv"   # a worktree's ../../shared
FLAG = DESIGN.parent / "flag_features_{shot}.csv"
PERTURBATION = 1e-12
FEATURES = ["v_jumpoff", "v_elastic", "v_plastic", "v_slope1", "v_slope2", "t_jumpoff", "t_elastic", "t_plastic",
            "t_slope1", "t_slope2"]
CALIBRATION = ["v_elastic", "v_plastic", "v_slope1", "v_slope2"]
FRONT_SLOPE_M_S_PER_US = 1000.0    # 1 m/s per ns: steeper output samples belong to a front


# ---------------------------------------------------------------------------------------------- child: one tree
def _features(result, settings):
    from shockcal.velocimetry.feature_tables import features_table

    table = pd.DataFrame([{"run": 0, "status": result.status, "reason": result.reason, "t_us": result.t_us,
                           "v_m_s": result.v_m_s}])
    return features_table(table, settings).iloc[0]


def _window_change(base, other, features, window_us):
    """(max |v_other - v_base| (m/s) on the common output times inside [t_jumpoff, t_jumpoff + window], the
    same outside the fronts: where |dv/dt| of the base trace is below FRONT_SLOPE_M_S_PER_US)."""
    n = min(len(base.t_us), len(other.t_us))
    t = base.t_us[:n]
    inside = (t >= features["t_jumpoff"]) & (t <= features["t_jumpoff"] + window_us)
    change = np.abs(other.v_m_s[:n] - base.v_m_s[:n])
    flat = inside & (np.abs(np.gradient(base.v_m_s[:n], t)) < FRONT_SLOPE_M_S_PER_US)
    return float(np.max(change[inside])), float(np.max(change[flat]))


def _study(model: str | None):
    """(the validated config, the design): the paper's config and design, or with `model` the config under that
    law and a seeded Latin hypercube of its box (a row per run; --rows of them are run)."""
    from shockcal.design.tables import latin_hypercube
    from shockcal.study.config import prior_bounds
    from shockcal.study.config_files import merge_config_files, merge_into
    from shockcal.study.validate import load_config, validate_config

    if model is None:
        return load_config(CONFIG), pd.read_csv(DESIGN)
    config = validate_config(merge_into(merge_config_files([CONFIG])[0], {"strength": {"model": model}}))
    return config, latin_hypercube(prior_bounds(config), 200, seed=0)


def child(args) -> None:
    from shockcal.hydro import ShotParameters, run_shot
    from shockcal.study.adapters import extractor_settings, hydro_inputs, shot_mapping
    from shockcal.study.config import shot_config

    config, design = _study(args.model)
    rows = []

    def add(shot, run, variant, result, settings, **extra):
        f = _features(result, settings)
        rows.append({"shot": shot, "run": run, "variant": variant, "status": f["status"],
                     **{c: float(f[c]) for c in FEATURES}, **extra})
        return f

    for shot in args.shots:
        spec = shot_config(config, shot)
        mapping = shot_mapping(config, shot)
        settings = extractor_settings(config, shot)
        inputs = hydro_inputs(config, spec)
        window = float(spec["analysis"]["window_after_arrival_us"])
        for record in design.iloc[: args.rows].to_dict("records"):
            run = int(record["run"])
            params = mapping.parameters(record)
            base = run_shot(params, *inputs)
            f = add(shot, run, "base", base, settings)
            for name in args.inputs:
                column = spec["velocity_input"] if name == "V" else name
                moved = dict(record, **{column: record[column] * (1.0 + PERTURBATION)})
                add(shot, run, f"perturbed_{column}", run_shot(mapping.parameters(moved), *inputs), settings)
            halved = run_shot(params, inputs[0], inputs[1], inputs[2].replace(cfl=inputs[2].cfl / 2))
            everywhere, off_fronts = _window_change(base, halved, f, window)
            add(shot, run, "cfl_half", halved, settings, window_change=everywhere, window_change_off_fronts=off_fronts)
            if isinstance(params, ShotParameters):      # Johnson-Cook's two doors
                mpa = ShotParameters(params.A_MPa, params.B_MPa, params.C, params.n, params.m, params.velocity_m_s,
                                     params.shear_modulus_GPa)
                add(shot, run, "mpa_door", run_shot(mpa, *inputs), settings)
            for cell_um in args.mesh:
                mesh_config = json.loads(json.dumps(config))
                mesh_config["hydro"]["cell_size_um"] = cell_um
                add(shot, run, f"mesh_{cell_um:g}", run_shot(params, *hydro_inputs(mesh_config, spec)), settings)
        if args.flag:
            from shockcal.simulators.builtin import simulate_design
            from shockcal.velocimetry.feature_tables import features_table

            traces = simulate_design(pd.read_csv(DESIGN).iloc[: args.flag], mapping, *inputs)
            table = features_table(traces, settings)
            for record in table.to_dict("records"):
                rows.append({"shot": shot, "run": int(record["run"]), "variant": "flag", "status": record["status"],
                             **{c: float(record[c]) for c in FEATURES}})
    speed = None
    if args.speed:
        spec = shot_config(config, "104S")
        mapping, inputs = shot_mapping(config, "104S"), hydro_inputs(config, spec)
        params = mapping.parameters(design.iloc[0].to_dict())
        run_shot(params, *inputs)
        best = np.inf
        for _ in range(3):
            start = time.process_time()
            run_shot(params, *inputs)
            best = min(best, time.process_time() - start)
        speed = {"cpu_s": best, "load": os.getloadavg()[0]}
    pd.to_pickle({"rows": pd.DataFrame(rows), "speed": speed}, args.out)


# ---------------------------------------------------------------------------------------------- parent: tables
def run_tree(src: Path, argv: list[str], label: str) -> dict:
    """The tree's rows (a child process on `src`), or those an earlier run kept when `src` is its .pkl file."""
    if src.suffix == ".pkl":
        print(f"{label}: {src} (kept from an earlier run)", flush=True)
        return pd.read_pickle(src)
    out = Path(tempfile.mkdtemp(prefix=f"bench-rate-{label}-")) / "rows.pkl"
    env = dict(os.environ, PYTHONPATH=str(src))
    start = time.time()
    subprocess.run([sys.executable, __file__, "--child", "--out", str(out), *argv], env=env, check=True)
    print(f"{label}: {src} done in {time.time() - start:.0f} s (its rows: {out}, for --before)", flush=True)
    return pd.read_pickle(out)


def _scaled(frame, columns):
    return frame[columns] * np.array([1e3 if c.startswith("t_") else 1.0 for c in columns])


def changes(rows: pd.DataFrame, variant_prefix: str) -> pd.DataFrame:
    """|variant - base| per feature (m/s, ns) for every (shot, run, variant) starting with the prefix."""
    base = rows[rows.variant == "base"].set_index(["shot", "run"])
    other = rows[rows.variant.str.startswith(variant_prefix)].set_index(["shot", "run"])
    diff = (_scaled(other, FEATURES) - _scaled(base.loc[other.index], FEATURES)).abs()
    return diff.assign(variant=other["variant"].values)


def print_side_by_side(title, before: pd.DataFrame, after: pd.DataFrame) -> None:
    print(f"\n{title}")
    print(pd.concat({"before": before, "after": after}, axis=1).to_string(float_format=lambda x: f"{x:.3g}"))


def report(before: dict, after: dict, args) -> None:
    b, a = before["rows"], after["rows"]
    runs = f"rows 0-{args.rows - 1}, shots {' '.join(args.shots)}"
    stats = lambda d: pd.DataFrame({"median": d[FEATURES].median(), "max": d[FEATURES].max()})  # noqa: E731
    print_side_by_side(f"a. rounding floor: |change| from a 1e-12 relative change of {', '.join(args.inputs)} "
                       f"({runs}; m/s, times ns)", stats(changes(b, "perturbed_")), stats(changes(a, "perturbed_")))
    cfl = lambda rows: pd.DataFrame({"max": pd.concat([changes(rows, "cfl_half")[FEATURES].max(),  # noqa: E731
                                                       pd.Series({"trace in window": rows.window_change.max(),
                                                                  "off the fronts": rows.window_change_off_fronts.max()})])})
    print_side_by_side(f"b. time step: CFL 0.25 against 0.5, max |change| ({runs}; m/s, times ns)", cfl(b), cfl(a))
    door = lambda rows: pd.DataFrame({"max": changes(rows, "mpa_door")[FEATURES].max()})  # noqa: E731
    if args.model is None:
        print_side_by_side(f"c. MPa door against the Mbar door, max |change| ({runs}; m/s, times ns)", door(b), door(a))
    same = lambda rows: rows[rows.variant == "base"].set_index(["shot", "run"])  # noqa: E731
    moved = (_scaled(same(a), FEATURES) - _scaled(same(b), FEATURES)).abs()
    print(f"\ng. the same runs in the two trees: |after - before| ({runs}; m/s, times ns)")
    print(pd.DataFrame({"median": moved.median(), "max": moved.max()}).to_string(float_format=lambda x: f"{x:.3g}"))
    if before["speed"]:
        print("\nd. speed: a 104S run (design row 0), CPU seconds, best of 3")
        print(f"   before {before['speed']['cpu_s']:.2f} s (load {before['speed']['load']:.1f})   "
              f"after {after['speed']['cpu_s']:.2f} s (load {after['speed']['load']:.1f})   "
              f"ratio {after['speed']['cpu_s'] / before['speed']['cpu_s']:.2f}")
    if args.mesh:
        mesh = lambda rows: (rows[rows.variant.str.startswith("mesh_")]  # noqa: E731
                             .set_index(["shot", "run", "variant"])[CALIBRATION])
        print_side_by_side(f"e. mesh: the calibration features (m/s) at {' / '.join(f'{m:g}' for m in args.mesh)} um",
                           mesh(b), mesh(a))
    if args.flag:
        def rms(rows):
            out = {}
            for shot in args.shots:
                flag = pd.read_csv(str(FLAG).format(shot=shot)).set_index("run")
                ours = rows[(rows.variant == "flag") & (rows.shot == shot) & (rows.status == "ok")].set_index("run")
                diff = ours[CALIBRATION] - flag.loc[ours.index, CALIBRATION]
                out[f"{shot} ({len(ours)} runs)"] = np.sqrt((diff ** 2).mean())
            return pd.DataFrame(out).T
        print_side_by_side(f"f. against FLAG: RMS of ours - FLAG (m/s), design runs 0-{args.flag - 1}", rms(b), rms(a))


def parse_args(argv):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--before", type=Path, help="the source tree to compare with (its src/), or the rows.pkl an "
                                                    "earlier run printed for it; required")
    parser.add_argument("--rows", type=int, default=30, help="design rows 0..N-1 (a, b, c, e)")
    parser.add_argument("--shots", nargs="+", default=["104S", "106S"])
    parser.add_argument("--inputs", nargs="+", default=["A", "B", "C", "n", "m", "V", "G1"],
                        help="design columns perturbed (V: the shot's velocity input)")
    parser.add_argument("--mesh", nargs="*", type=float, default=[], help="cell sizes (um) for e, e.g. 8 4 2")
    parser.add_argument("--flag", type=int, default=0, help="design runs 0..N-1 against FLAG (f)")
    parser.add_argument("--speed", action="store_true", help="d: time a 104S run in each tree")
    parser.add_argument("--model", default=None, help="another strength law (its box's hypercube rows; no c, no f)")
    parser.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    parser.add_argument("--out", type=Path, help=argparse.SUPPRESS)
    return parser.parse_args(argv)


def main(argv=None) -> None:
    argv = sys.argv[1:] if argv is None else argv
    args = parse_args(argv)
    if args.child:
        child(args)
        return
    if args.before is None:
        sys.exit("rate_return_compare.py: --before: give the source tree to compare with (its src/)")
    passed = ["--rows", str(args.rows), "--shots", *args.shots, "--inputs", *args.inputs, "--flag", str(args.flag),
              *(["--mesh", *map(str, args.mesh)] if args.mesh else []), *(["--speed"] if args.speed else []),
              *(["--model", args.model] if args.model else [])]
    print(f"load average at start: {os.getloadavg()[0]:.2f}", flush=True)
    before = run_tree(args.before, passed, "before")
    after = run_tree(ROOT / "src", passed, "after")
    report(before, after, args)


if __name__ == "__main__":
    main()
