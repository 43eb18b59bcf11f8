"""`shockcal flow-stress`: a strength law's flow stress against plastic strain at one state (user units)."""

from __future__ import annotations

from shockcal.cli import add_command

EXAMPLE_FLOW_STRESS = """\
shockcal flow-stress --model johnson-cook --param A_MPa=335 --param B_MPa=425 --param C=0.0335 \\
    --param n=0.42 --param m=1.225 --material al5083 --strain-rate 1e5 --temperature 298"""


def register(subparsers) -> None:
    p = add_command(subparsers, "flow-stress", example=EXAMPLE_FLOW_STRESS,
                    help="tabulate a strength law's flow stress (MPa) against plastic strain at one state",
                    description="Flow stress (MPa) of a strength law (johnson-cook, steinberg-guinan, ptw, "
                                "zerilli-armstrong) against equivalent plastic strain, at a constant strain rate, "
                                "temperature, pressure and density ratio. Parameters by their unit-suffixed names "
                                "(shockcal.hydro.laws.declarations), e.g. --param A_MPa=270; the law's material "
                                "constants (melt temperature, density, molar mass) from --material unless given by "
                                "--param. At or above the law's melting temperature the flow stress is zero, and the "
                                "table says so.")
    p.add_argument("--model", required=True,
                   help="johnson-cook (jc), steinberg-guinan (sg), ptw, zerilli-armstrong (za)")
    p.add_argument("--param", action="append", default=[], metavar="NAME=VALUE", help="a parameter (repeat)")
    p.add_argument("--material", metavar="NAME",
                   help="a library material (shockcal materials) giving the law's material constants; without it, "
                        "give them by --param")
    p.add_argument("--strain-rate", type=float, required=True, help="equivalent strain rate (1/s)")
    p.add_argument("--temperature", type=float, required=True, help="temperature (K)")
    p.add_argument("--pressure", type=float, default=0.0, help="pressure (GPa, positive in compression; default 0)")
    p.add_argument("--density-ratio", type=float, default=1.0, help="rho / rho0 (default 1)")
    p.add_argument("--max-strain", type=float, default=0.2, help="largest plastic strain of the table (default 0.2)")
    p.add_argument("--points", type=int, default=11, help="rows of the table (default 11)")
    p.set_defaults(func=run)


def parse_params(pairs: list[str]) -> dict[str, float]:
    """['A_MPa=270', ...] -> {'A_MPa': 270.0}; a malformed pair or a repeated name is an InputError."""
    from shockcal.errors import InputError

    values: dict[str, float] = {}
    for pair in pairs:
        name, sep, text = pair.partition("=")
        name = name.strip()
        if not sep or not name:
            raise InputError(f"--param: '{pair}' is not NAME=VALUE")
        if name in values:
            raise InputError(f"--param: {name} given twice")
        try:
            values[name] = float(text)
        except ValueError:
            raise InputError(f"--param {name}: '{text}' is not a number") from None
    return values


def run(args) -> int:
    import math

    import numpy as np

    from shockcal.errors import InputError
    from shockcal.hydro.laws import (
        check_given,
        flow_stress_curve,
        get_law,
        law_values,
        melt_temperature_K,
        shear_modulus_gpa,
    )
    from shockcal.hydro.material_library import load_material

    law = get_law(args.model)
    given = parse_params(args.param)
    check_given(law, given)
    state = {"--strain-rate": args.strain_rate, "--temperature": args.temperature, "--pressure": args.pressure,
             "--density-ratio": args.density_ratio, "--max-strain": args.max_strain}
    for option, value in state.items():
        if not math.isfinite(value):
            raise InputError(f"{option}: {value} is not a finite number")
    for option in ("--strain-rate", "--temperature", "--max-strain"):
        if state[option] < 0:
            raise InputError(f"{option}: {state[option]} is negative")
    if args.density_ratio <= 0:
        raise InputError(f"--density-ratio: {args.density_ratio} is not positive")
    if args.points < 2:
        raise InputError(f"--points: {args.points} is fewer than 2")
    values = law_values(law, given, None if args.material is None else load_material(args.material))
    strains = np.linspace(0.0, args.max_strain, args.points)
    stress = flow_stress_curve(law, values, strains, args.strain_rate, args.temperature, args.pressure,
                               args.density_ratio)
    for eps, y in zip(strains, stress):
        if not (math.isfinite(y) and y >= 0.0):
            raise InputError(f"{law.name}: flow stress {y} MPa at plastic strain {eps:g} is not a finite non-negative "
                             "number (check the parameters)")
    print(f"# {law.title}; {law.reference}")
    print(f"# strain rate {args.strain_rate:g} /s, T {args.temperature:g} K, P {args.pressure:g} GPa, "
          f"rho/rho0 {args.density_ratio:g}")
    G = shear_modulus_gpa(law, values, args.temperature, args.pressure, args.density_ratio)
    if G is not None:
        print(f"# shear modulus {G:.6g} GPa")
    melt = melt_temperature_K(law, values, args.density_ratio)
    if melt is not None and args.temperature >= melt:
        print(f"# molten: T {args.temperature:g} K is at or above the law's melting temperature {melt:.6g} K "
              f"(at rho/rho0 {args.density_ratio:g}), where its flow stress is zero")
    print(f"{'plastic_strain':>14} {'flow_stress_MPa':>16}")
    for eps, y in zip(strains, stress):
        print(f"{eps:14.4f} {y:16.6g}")
    return 0
