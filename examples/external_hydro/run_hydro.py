"""An external hydrocode for shockcal's `command` simulator: reads a plain-text deck, writes a CSV trace.

    python run_hydro.py deck.txt trace.csv [--fault MODE --fault-fraction P --seed S]

It runs shockcal's own 1D hydrocode (`shockcal.hydro.run_shot`) in this process, standing in for a
lab's code: copy it and swap `simulate` for a call of yours. The deck is `key = value` lines (units in
the names, deck.txt); the trace is `t_us,v_m_s` (microseconds after impact, free-surface velocity in
m/s), numbers written as the shortest decimal that reads back as the same double. Exit code 0: the
trace is written; 2: a bad deck; 3: the hydrocode failed (the reason on stderr).

`--fault` makes the runs it picks misbehave, for tests of shockcal's failure capture (a run is picked
when a uniform draw seeded by (S, the deck's run) is below P): `exit` exits 3 with a message on stderr,
`hang` sleeps past any timeout, `half` writes the first half of the trace's lines and exits 0, `cm-us`
writes the velocities in cm/us under the m/s header.
"""

from __future__ import annotations

import argparse
import sys
import time

FAULTS = ("exit", "hang", "half", "cm-us")
TEXT_KEYS = {"shot"}


def read_deck(path: str) -> dict:
    """The deck's values: numbers as floats (`run` as int), `shot` as text."""
    values = {}
    with open(path, encoding="utf-8") as handle:
        for number, line in enumerate(handle, start=1):
            line = line.split("#", 1)[0].strip()
            if not line:
                continue
            key, sep, value = (part.strip() for part in line.partition("="))
            if not sep:
                sys.exit(f"run_hydro: {path} line {number}: not `key = value`")
            values[key] = value if key in TEXT_KEYS else int(value) if key == "run" else float(value)
    return values


def simulate(deck: dict):
    """(t_us, v_m_s, status, reason) of the deck's run through shockcal's hydrocode."""
    from shockcal.hydro import Geometry, HydroSettings, MaterialProperties, ShotParameters, run_shot

    params = ShotParameters.from_table_iv(deck["A_Mbar"], deck["B_Mbar"], deck["C"], deck["n"], deck["m"],
                                          deck["velocity_cm_us"], deck["shear_modulus_Mbar"])
    geometry = Geometry(flyer_mm=deck["flyer_mm"], target_mm=deck["target_mm"], end_us=deck["end_time_us"],
                        initial_temperature_K=deck["initial_temperature_K"])
    material = MaterialProperties(**{k: deck[k] for k in MaterialProperties.model_fields if k in deck})
    settings = HydroSettings(**{k: deck[k] for k in HydroSettings.model_fields})
    result = run_shot(params, geometry, material, settings)
    return result.t_us, result.v_m_s, result.status, result.reason


def write_trace(path: str, t_us, v_m_s, velocity_factor: float = 1.0, fraction: float = 1.0) -> None:
    lines = [f"{t!r},{v * velocity_factor!r}" for t, v in zip(t_us.tolist(), v_m_s.tolist())]
    with open(path, "w", encoding="utf-8") as handle:
        handle.write("t_us,v_m_s\n")
        handle.write("\n".join(lines[: int(len(lines) * fraction)]) + "\n")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("deck")
    parser.add_argument("trace")
    parser.add_argument("--fault", choices=FAULTS)
    parser.add_argument("--fault-fraction", type=float, default=1.0)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args(argv)
    deck = read_deck(args.deck)
    fault = None
    if args.fault:
        import numpy as np

        fault = args.fault if np.random.default_rng([args.seed, deck["run"]]).random() < args.fault_fraction else None
    if fault == "exit":
        print(f"run_hydro: run {deck['run']}: injected failure", file=sys.stderr)
        return 3
    if fault == "hang":
        time.sleep(3600)
    t_us, v_m_s, status, reason = simulate(deck)
    if status != "ok":
        print(f"run_hydro: run {deck['run']}: {reason}", file=sys.stderr)
        return 3
    write_trace(args.trace, t_us, v_m_s, velocity_factor=1e-4 if fault == "cm-us" else 1.0,
                fraction=0.5 if fault == "half" else 1.0)
    return 0


if __name__ == "__main__":
    sys.exit(main())
