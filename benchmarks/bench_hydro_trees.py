"""The hydrocode's CPU time in several source trees side by side, runs alternating: printed, never asserted.

    python benchmarks/bench_hydro_trees.py old=../old/src main=../main/src new=src [--repeats 5] [--laws]

Each tree runs in a child process of its own (PYTHONPATH; numba caches beside each tree's sources) that compiles and runs each case
once, then the parent asks the children in turn, tree after tree, for one timed run at a time, so a change of
the machine's load falls on every tree alike. Per case and tree: CPU seconds (time.process_time, not wall: the
machine may be shared) best and median of --repeats runs, the load average while they ran, and each tree's
ratio to the first tree's best. Cases: 104S at the config's mesh and end time with row 0 of the paper's
design (design.csv, Table IV units); with --laws also a thin 104S-like run per strength law (flyer 1 mm,
target 1.5 mm, 0.6 us, 204 m/s; the laws' Al parameter sets of config/models.yaml's sources, as
tests/test_hydro_laws.py runs them). A tree without a law's kernels (older than the law) shows n/a.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CONFIG = ROOT / "config" / "config.yaml"
V_104S_M_S = 204.0
THIN_MM_US = dict(flyer_mm=1.0, target_mm=1.5, end_us=0.6)
LAW_SETS = {  # user units, as tests/test_hydro_laws.py's LAW_RUNS (the shot's G1 where the law has no modulus law)
    "johnson-cook": ({"A_MPa": 170, "B_MPa": 425, "C": 0.0335, "n": 0.42, "m": 1.225}, 27.0),
    "steinberg-guinan": ({"Y0_GPa": 0.29, "Ymax_GPa": 0.68, "beta": 125.0, "n": 0.1, "G0_GPa": 27.6, "dGdP": 1.8,
                          "dGdT_over_G0_per_K": -6.16e-4}, None),
    "ptw": (dict(theta=0.02, p=2.0, s0=0.0080, sinf=0.0070, kappa=0.3, gamma=1e-3, y0=0.0056, yinf=0.0052, y1=0.02,
                 y2=0.4, beta=0.25, G0_GPa=27.0, alpha=0.23), None),
    "zerilli-armstrong": (dict(C0_MPa=250.0, C2_MPa=500.0, C3_per_K=0.0028, C4_per_K=0.000115), 27.0),
}


# ---------------------------------------------------------------------------------------------- child: one tree
def _cases(laws: bool) -> dict:
    """Case name -> a function that runs it once (in the child's tree)."""
    import pandas as pd

    from shockcal.hydro import ShotParameters, run_shot
    from shockcal.reference import reference_dir
    from shockcal.study.adapters import hydro_inputs
    from shockcal.study.config import shot_config
    from shockcal.study.validate import load_config

    config = load_config(CONFIG)
    design = (reference_dir() or ROOT.parents[1] / "shared" / "data" / "al5083") / "design.csv"
    row = pd.read_csv(design).iloc[0]
    params = ShotParameters.from_table_iv(row["A"], row["B"], row["C"], row["n"], row["m"], row["V1"], row["G1"])
    inputs = hydro_inputs(config, shot_config(config, "104S"))
    cases = {"104S row 0": lambda: run_shot(params, *inputs)}
    if laws:
        try:
            from shockcal.hydro import Geometry, LawShotParameters
            from shockcal.hydro.material_library import load_material
        except ImportError:
            return cases
        material, thin = load_material("al5083"), Geometry(**THIN_MM_US)
        for name, (values, G1) in LAW_SETS.items():
            shot = (LawShotParameters(name, values, V_104S_M_S, G1) if G1 is not None
                    else LawShotParameters(name, values, V_104S_M_S))
            cases[f"thin {name}"] = lambda shot=shot: run_shot(shot, thin, material)
    return cases


def child(laws: bool) -> None:
    """Compile and run each case once, then answer `run CASE` lines with the CPU seconds of one run."""
    cases = _cases(laws)
    for run in cases.values():
        run()
    print("ready " + "|".join(cases), flush=True)
    for line in sys.stdin:
        name = line.strip()
        if name not in cases:
            print("n/a", flush=True)
            continue
        start = time.process_time()
        cases[name]()
        print(f"{time.process_time() - start:.6f}", flush=True)


# ---------------------------------------------------------------------------------------------- parent
def _start(src: Path, laws: bool) -> tuple[subprocess.Popen, list[str]]:
    env = dict(os.environ, PYTHONPATH=str(src.resolve()))
    proc = subprocess.Popen([sys.executable, __file__, "--child", *(["--laws"] if laws else [])], env=env,
                            stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    ready = proc.stdout.readline().split(maxsplit=1)
    if not ready or ready[0] != "ready":
        sys.exit(f"bench_hydro_trees.py: the child for {src} did not start")
    return proc, ready[1].strip().split("|")


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("trees", nargs="*", help="LABEL=SRC: a source tree's src/ under a label")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--laws", action="store_true", help="also a thin run per strength law")
    parser.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.child:
        child(args.laws)
        return
    trees = [tree.split("=", 1) for tree in args.trees]
    if not trees or any(len(tree) != 2 for tree in trees):
        sys.exit("bench_hydro_trees.py: give each tree as LABEL=SRC")
    print(f"load average at start: {os.getloadavg()[0]:.2f} (CPU seconds are inflated when > 0)", flush=True)
    children = {label: _start(Path(src), args.laws) for label, src in trees}
    cases = list(dict.fromkeys(case for _, names in children.values() for case in names))
    print(f"{'case':26}{'tree':>8}{'best s':>9}{'median s':>10}{'load':>7}{'x first':>9}")
    for case in cases:
        times = {label: [] for label in children}
        loads = []
        for _ in range(args.repeats):
            for label, (proc, _) in children.items():
                proc.stdin.write(case + "\n")
                proc.stdin.flush()
                answer = proc.stdout.readline().strip()
                if answer != "n/a":
                    times[label].append(float(answer))
            loads.append(os.getloadavg()[0])
        first = min(times[trees[0][0]]) if times[trees[0][0]] else float("nan")
        for label, seconds in times.items():
            if not seconds:
                print(f"{case:26}{label:>8}{'n/a':>9}")
                continue
            print(f"{case:26}{label:>8}{min(seconds):9.3f}{statistics.median(seconds):10.3f}"
                  f"{statistics.mean(loads):7.1f}{min(seconds) / first:9.2f}", flush=True)
    for proc, _ in children.values():
        proc.stdin.close()
        proc.wait()


if __name__ == "__main__":
    main()
