"""Writes the traces the floor tests compare with: the hydrocode of this tree with its flow-stress floor skips
removed (every cell's rate-free flow stress evaluated every step), so the tests show the skips change no trace.

    python tests/data/make_floor_free_traces.py

Copies src/ to a temporary directory, makes `plastic_return`'s floor test never skip, and runs in a child
process on that copy: tests/test_hydro.py's JC_FLOOR_CASES (-> traces_without_flow_floors.npz) and
tests/test_hydro_laws.py's LAW_FLOOR_CASES (-> law_traces_without_law_floors.npz). Rerun after any change to
the return's physics (not after a change to the floors: that is what the tests check).
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
FLOOR_TEST = "    if equivalent <= LAW_FLOOR_SLACK * law_flow_stress_floor("


def child() -> None:
    import numpy as np

    sys.path.insert(0, str(ROOT / "tests"))
    from test_hydro import JC_FLOOR_CASES
    from test_hydro_laws import AL5083, LAW_FLOOR_CASES, THIN

    import shockcal.hydro.plastic_return as patched
    from shockcal.hydro import ShotParameters, run_shot
    from shockcal.study.adapters import hydro_inputs
    from shockcal.study.validate import load_config
    assert "if False and" in Path(patched.__file__).read_text(), "the child must run on the patched copy"
    config = load_config(ROOT / "config" / "config.yaml")
    config["hydro"].update(cell_size_um=4.0, end_time_us=0.6)
    inputs = hydro_inputs(config, {"flyer_mm": 1.0, "target_mm": 1.5})
    np.savez(HERE / "traces_without_flow_floors.npz",
             **{name: run_shot(ShotParameters.from_table_iv(*table_iv), *inputs).v_m_s
                for name, table_iv in JC_FLOOR_CASES.items()})
    np.savez(HERE / "law_traces_without_law_floors.npz",
             **{name: run_shot(params, THIN, AL5083).v_m_s for name, params in LAW_FLOOR_CASES.items()})


def main() -> None:
    with tempfile.TemporaryDirectory() as tmp:
        copy = Path(tmp) / "src"
        shutil.copytree(ROOT / "src", copy, ignore=shutil.ignore_patterns("__pycache__"))
        module = copy / "shockcal" / "hydro" / "plastic_return.py"
        text = module.read_text()
        assert text.count(FLOOR_TEST) == 1, "plastic_return's floor test moved: update FLOOR_TEST"
        module.write_text(text.replace(FLOOR_TEST, FLOOR_TEST.replace("if ", "if False and ")))
        env = {**os.environ, "PYTHONPATH": str(copy), "NUMBA_CACHE_DIR": str(Path(tmp) / "numba")}
        subprocess.run([sys.executable, __file__, "--child"], check=True, env=env, cwd=ROOT)


if __name__ == "__main__":
    child() if "--child" in sys.argv else main()
