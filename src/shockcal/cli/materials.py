"""`shockcal materials`: the material library, each entry with its EOS and its source."""

from __future__ import annotations

from shockcal.cli import add_command


def register(subparsers) -> None:
    p = add_command(subparsers, "materials", example="shockcal materials\nshockcal materials copper",
                    help="list the material library a config names (material: {name: copper}) with its sources",
                    description="The material library (src/shockcal/materials/<name>.yaml): each entry's name, "
                                "description, density, EOS as given and as the cubic the hydrocode uses, and "
                                "source. A config names one with `material: {name: <name>}` and may override any "
                                "of its keys.")
    p.add_argument("names", nargs="*", help="entries to show in full (default: one line each for all)")
    p.set_defaults(func=run)


def run(args) -> int:
    from shockcal.hydro.material_library import library_entry, material_names, material_properties

    if not args.names:
        for name in material_names():
            entry = library_entry(name)
            print(f"{name:10s} {entry['description']}: {' '.join(entry['source'].split())}")
        return 0
    for name in args.names:
        entry = library_entry(name, "materials")
        material = material_properties(entry["material"])
        given = ", ".join(f"{k} = {v:g}" for k, v in entry["material"]["eos"].items())
        print(f"{name}: {entry['description']}\n  rho0_g_cc = {material.rho0_g_cc:g}\n  eos (as given): {given}\n"
              f"  eos (cubic): c1_Mbar = {material.c1_Mbar:.6g}, c2_Mbar = {material.c2_Mbar:.6g}, "
              f"c3_Mbar = {material.c3_Mbar:.6g}, gamma0 = {material.gamma0:g}\n"
              f"  T_ref_K = {material.T_ref_K:g}, T_melt_K = {material.T_melt_K:g}, "
              f"cv_J_per_kg_K = {material.cv_J_per_kg_K:g}, strain_rate_ref_per_s = {material.strain_rate_ref_per_s:g}\n"
              f"  source: {' '.join(entry['source'].split())}")
    return 0
