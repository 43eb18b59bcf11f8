"""Unit factors between the hydrocode's units (cm, us, g/cc, Mbar; 1 Mbar = 1 g/cc (cm/us)^2, so
specific energy is in (cm/us)^2) and the units of the config and the tables (mm, um, ns, m/s, GPa,
J/kg/K, 1/s). Each name says its direction: a value in X times X_TO_Y is the value in Y.

What a user reads (summaries, InferenceData, report tables) is in MPa (stresses), GPa (moduli) and m/s:
`user_unit` says which for a declared unit, `unit_factor` converts, `unit_name` puts the unit in the
name (`A_MPa`, `V1_m_s`), and `user_columns` does all three for a table's columns."""

from __future__ import annotations

from collections.abc import Collection, Mapping

MM_TO_CM = 0.1
UM_TO_CM = 1.0e-4
NS_TO_US = 1.0e-3
J_PER_KG_TO_CODE = 1.0e-8          # 1 J/kg in (cm/us)^2
PER_S_TO_PER_US = 1.0e-6
CM_US_TO_M_S = 1.0e4
MBAR_TO_GPA = 100.0
MBAR_TO_MPA = 1.0e5

# a velocity input's unit (config `inputs.<name>.unit`) -> the factor to m/s
VELOCITY_TO_M_S = {"cm/us": CM_US_TO_M_S, "m/s": 1.0, "km/s": 1.0e3, "mm/us": 1.0e3}

# The units a user reads (MPa, GPa, m/s): a value in a unit of PRESSURE_IN_MPA or VELOCITY_TO_M_S converts to
# another of the same table by the ratio of their factors.
PRESSURE_IN_MPA = {"Mbar": MBAR_TO_MPA, "kbar": 100.0, "GPa": 1.0e3, "MPa": 1.0}
# the paper's units and the hydrocode's (config `inputs.<name>.unit`), shown to a user in another
PAPER_UNITS = ("Mbar", "kbar", "cm/us", "km/s", "mm/us")
# a unit -> how it reads in a column name (`A_MPa`, `V1_m_s`); others: their characters outside [A-Za-z0-9] as "_"
UNIT_SUFFIXES = {"m/s": "m_s", "1/s": "per_s", "1/K": "per_K", "g/cc": "g_per_cc", "g/mol": "g_per_mol"}
DIMENSIONLESS = ("-", "", "1")


def user_unit(unit: str, modulus: bool = False) -> str:
    """The unit a user reads for a value declared in `unit`: a pressure in one of the paper's units (Mbar,
    kbar) in MPa, or in GPa when it is a modulus (`modulus`: a shear modulus or its increment); a velocity
    in cm/us, km/s or mm/us in m/s; any other unit (MPa, GPa, m/s, K, dimensionless, ...) as declared."""
    unit = str(unit).strip()
    if unit not in PAPER_UNITS:
        return unit
    return ("GPa" if modulus else "MPa") if unit in PRESSURE_IN_MPA else "m/s"


def user_units(units: Mapping[str, str], moduli: Collection[str] = ()) -> dict[str, str]:
    """Each name of `units` (name -> declared unit) -> its `user_unit`, `moduli` naming the moduli."""
    return {name: user_unit(unit, modulus=name in moduli) for name, unit in units.items()}


def unit_factor(unit: str, to: str) -> float:
    """The factor from `unit` to `to` (a value in `unit` times it is the value in `to`): 1 for equal units,
    else both pressures (`PRESSURE_IN_MPA`) or both velocities (`VELOCITY_TO_M_S`); ValueError otherwise."""
    unit, to = str(unit).strip(), str(to).strip()
    if unit == to:
        return 1.0
    for table in (PRESSURE_IN_MPA, VELOCITY_TO_M_S):
        if unit in table and to in table:
            return table[unit] / table[to]
    raise ValueError(f"no factor from {unit!r} to {to!r}")


def unit_name(name: str, unit: str) -> str:
    """`name` with its unit as a suffix, the way every table and file names a value a user reads: A, MPa ->
    A_MPa; V1, m/s -> V1_m_s; a dimensionless value, or a name that already ends in its unit (Y0_GPa), as it is."""
    unit = str(unit).strip()
    if unit in DIMENSIONLESS:
        return name
    suffix = UNIT_SUFFIXES.get(unit) or "".join(c if c.isalnum() else "_" for c in unit).strip("_")
    return name if name.endswith(f"_{suffix}") else f"{name}_{suffix}"


def user_columns(units: Mapping[str, str], to_units: Mapping[str, str]) -> dict[str, tuple[str, str, float]]:
    """Each name of `units` (name -> declared unit) -> (its name for a user, its user unit, the factor to
    it): the user unit from `to_units` (absent: the declared one; `user_units` gives them), the name from
    `unit_name`."""
    out = {}
    for name, unit in units.items():
        to = to_units.get(name, unit)
        out[name] = (unit_name(name, to), to, unit_factor(unit, to))
    return out
