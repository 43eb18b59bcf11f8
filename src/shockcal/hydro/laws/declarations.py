"""Every strength law's parameters, declared in one place: name (unit-suffixed, as the user writes it),
the symbol of the paper and the kernel's field, user unit, factor to code units (Mbar, K, 1/us, g/cc,
g/mol; `shockcal.units`), meaning, and either a default (a convention of the law: Steinberg-Guinan's eps_i,
Zerilli-Armstrong's reference rate) or the `MaterialProperties` field that gives it (`material`: a property
of the study's material, density, molar mass, melt temperature, filled by `shockcal.hydro.laws.law_values`);
calibrated parameters have neither.

A user value times `to_code` is the kernel's value. Prior boxes for aluminium, with sources, are in
config/models.yaml (`shockcal.hydro.laws.boxes`).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

from shockcal.hydro.laws.johnson_cook import (
    JohnsonCook,
    johnson_cook_flow_stress,
    johnson_cook_flow_stress_floor,
    johnson_cook_flow_stress_from_hardening,
    johnson_cook_hardening,
    johnson_cook_hardening_after,
    johnson_cook_plastic_increment,
    johnson_cook_plastic_increment_warm,
    johnson_cook_rate_free_flow_stress,
    johnson_cook_remember_floor,
)
from shockcal.hydro.laws.preston_tonks_wallace import (
    PrestonTonksWallace,
    ptw_flow_stress,
    ptw_flow_stress_at,
    ptw_flow_stress_floor,
    ptw_hardening,
    ptw_shear_modulus,
)
from shockcal.hydro.laws.steinberg_guinan import (
    SteinbergGuinan,
    steinberg_guinan_flow_stress,
    steinberg_guinan_flow_stress_at,
    steinberg_guinan_flow_stress_floor,
    steinberg_guinan_hardening,
    steinberg_guinan_melt_temperature,
    steinberg_guinan_shear_modulus,
)
from shockcal.hydro.laws.zerilli_armstrong import (
    ZerilliArmstrong,
    zerilli_armstrong_flow_stress,
    zerilli_armstrong_flow_stress_floor,
    zerilli_armstrong_plastic_increment,
)
from shockcal.units import MBAR_TO_GPA, PER_S_TO_PER_US

GPA_TO_MBAR = 1.0 / MBAR_TO_GPA
MPA_TO_MBAR = 1.0e-3 / MBAR_TO_GPA


@dataclass(frozen=True)
class Param:
    """One parameter of a law: `name` as the user gives it (unit-suffixed unless dimensionless),
    `field` of the kernel's named tuple, `unit` of the user value, `to_code` its factor to code units;
    `default` its value when not given, or `material` the `MaterialProperties` field (same unit) that gives
    it when not given."""

    name: str
    field: str
    unit: str
    to_code: float
    meaning: str
    default: float | None = None
    material: str | None = None

    @property
    def calibrated(self) -> bool:
        """A parameter a study must box: neither a declared default nor a material constant."""
        return self.default is None and self.material is None


def _p(name, field, unit, to_code, meaning, default=None, material=None) -> Param:
    return Param(name, field, unit, to_code, meaning, default, material)


def _mpa(name, field, meaning, default=None) -> Param:
    return _p(name, field, "MPa", MPA_TO_MBAR, meaning, default)


def _gpa(name, field, meaning, default=None) -> Param:
    return _p(name, field, "GPa", GPA_TO_MBAR, meaning, default)


def _one(name, meaning, default=None) -> Param:
    return _p(name, name, "-", 1.0, meaning, default)


@dataclass(frozen=True)
class Law:
    """A strength law: its kernels (code units, `flow_stress(law, eps_p, rate, T, P, eta)`; the
    optional `shear_modulus(law, P, T, eta)`), its parameters and the constraints on their values
    (text, predicate on the user values); `melt_temperature(law, eta)` (K), where the strength vanishes, for
    the laws that have one. Optional kernels that spare the solver work (`shockcal.hydro.laws.kernels`):
    `flow_stress_at(law, G, eps_p, rate, T, P, eta)` for a law with a modulus law (the flow stress with
    the cell's G, not recomputed), `flow_stress_floor(law, hard, G, T, eta, flow_floor, floor_hotter,
    floor_T)`, a proven lower bound of the flow stress at any rate from `hardening(law, eps_p)`, which the
    solver caches per cell, and from the floor `remember_floor(law, G, eps_p, T, eta, ...)` sets after a full
    evaluation found the cell elastic; `flow_stress_from_hardening(law, hard, rate, T)`, the flow stress from
    that cached hardening (for a law whose flow stress is its hardening times factors of rate and T).
    `rate_dependent`: whether the flow stress has a rate term, which the solver's return then evaluates at the
    step's plastic strain rate (`shockcal.hydro.consistent_return`); `plastic_increment(law, equivalent,
    rate_free, G, dt, hard, eps_p, T, P, eta)`, the law's own solution of that return (Johnson-Cook's and
    Zerilli-Armstrong's closed forms). Kernels that spare a cell that stays plastic its pows and logs, each the
    same value to rounding (`shockcal.hydro.series`): `hardening_after(law, hard, eps_p, d_eps)`, the hardening
    after an increment from the cached one; `rate_free_flow_stress(law, hard, T, power_T, power)`, the flow
    stress at zero rate from a thermal power the cell remembers, with the renewed memory;
    `plastic_increment_warm(law, equivalent, rate_free, G, dt, hard, eps_p, T, P, eta, x_warm, rate_warm)`,
    `plastic_increment` started at the cell's last plastic rate, with the renewed warm start. A
    study's design columns (`column`): the kernel's fields in code units for a law with `code_unit_columns`
    (Johnson-Cook, whose box a study gives in `inputs`), else the declared names in user units (a box in
    `strength.inputs` or config/models.yaml). `roles` names the parameters that study code reads by their
    part in the law (`role_column`): the emulator's power inputs (eps^n, T*^m) and the next-shot check's
    initial yield stress."""

    name: str
    title: str
    reference: str
    params: tuple[Param, ...]
    code_type: type
    flow_stress: Callable
    shear_modulus: Callable | None = None
    constraints: tuple[tuple[str, Callable[[Mapping[str, float]], bool]], ...] = ()
    melt_temperature: Callable | None = None
    flow_stress_at: Callable | None = None
    hardening: Callable | None = None
    flow_stress_floor: Callable | None = None
    remember_floor: Callable | None = None
    flow_stress_from_hardening: Callable | None = None
    rate_dependent: bool = True
    plastic_increment: Callable | None = None
    hardening_after: Callable | None = None
    rate_free_flow_stress: Callable | None = None
    plastic_increment_warm: Callable | None = None
    code_unit_columns: bool = False
    roles: Mapping[str, str] = field(default_factory=dict)

    def param(self, name: str) -> Param:
        return next(p for p in self.params if p.name == name)

    def names(self) -> list[str]:
        return [p.name for p in self.params]

    def column(self, param: Param) -> str:
        """The design-table column (study input) that holds `param`: its kernel `field`, in code units, for a
        law with `code_unit_columns` (Johnson-Cook: A, B in Mbar, C, n, m), else its declared `name`."""
        return param.field if self.code_unit_columns else param.name

    def calibrated_columns(self) -> list[str]:
        """The columns of the parameters a study must box: neither a declared default nor a material constant."""
        return [self.column(p) for p in self.params if p.calibrated]

    def role_column(self, role: str) -> str | None:
        """The column of the parameter that plays `role` (`roles`: "hardening_exponent", "rate_coefficient",
        "thermal_exponent", "yield_stress"), or None when the law has no such parameter."""
        name = self.roles.get(role)
        return None if name is None else self.column(self.param(name))


JOHNSON_COOK = Law(
    "johnson-cook", "Johnson-Cook (1983), the hydrocode's law",
    "Johnson & Cook, Proc. 7th Int. Symp. Ballistics (1983)",
    (
        _mpa("A_MPa", "A", "yield stress at eps_p = 0"),
        _mpa("B_MPa", "B", "hardening modulus"),
        _one("C", "strain-rate coefficient"),
        _one("n", "hardening exponent"),
        _one("m", "thermal-softening exponent"),
        _p("T_ref_K", "T_ref", "K", 1.0, "reference (room) temperature", material="T_ref_K"),
        _p("T_melt_K", "T_melt", "K", 1.0, "melt temperature", material="T_melt_K"),
        _p("rate_ref_per_s", "rate_ref", "1/s", PER_S_TO_PER_US, "reference strain rate",
           material="strain_rate_ref_per_s"),
    ),
    JohnsonCook, johnson_cook_flow_stress,
    constraints=(("T_melt_K > T_ref_K", lambda v: v["T_melt_K"] > v["T_ref_K"]),
                 ("rate_ref_per_s > 0", lambda v: v["rate_ref_per_s"] > 0)),
    melt_temperature=lambda law, eta: law.T_melt,
    hardening=johnson_cook_hardening, flow_stress_floor=johnson_cook_flow_stress_floor,
    remember_floor=johnson_cook_remember_floor, flow_stress_from_hardening=johnson_cook_flow_stress_from_hardening,
    plastic_increment=johnson_cook_plastic_increment, hardening_after=johnson_cook_hardening_after,
    rate_free_flow_stress=johnson_cook_rate_free_flow_stress,
    plastic_increment_warm=johnson_cook_plastic_increment_warm,
    code_unit_columns=True,
    roles={"yield_stress": "A_MPa", "rate_coefficient": "C", "hardening_exponent": "n", "thermal_exponent": "m"},
)

STEINBERG_GUINAN = Law(
    "steinberg-guinan", "Steinberg-Guinan (1980), rate-independent",
    "Steinberg, Cochran & Guinan, J. Appl. Phys. 51, 1498 (1980)",
    (
        _gpa("Y0_GPa", "Y0", "yield stress at eps_p = eps_i, P = 0, T = 300 K"),
        _gpa("Ymax_GPa", "Ymax", "cap of the work-hardened yield stress"),
        _one("beta", "hardening coefficient"),
        _one("n", "hardening exponent"),
        _one("eps_i", "initial equivalent plastic strain", 0.0),
        _gpa("G0_GPa", "G0", "shear modulus at P = 0, T = 300 K"),
        _p("dGdP", "dGdP", "-", 1.0, "G'_P = dG/dP"),
        _p("dGdT_over_G0_per_K", "dGdT_over_G0", "1/K", 1.0, "G'_T / G0 = (dG/dT) / G0 (negative)"),
        _p("T_m0_K", "T_m0", "K", 1.0, "melt temperature at eta = 1", material="melt_T_m0_K"),
        _p("gamma0", "gamma0", "-", 1.0, "Grueneisen coefficient of the melt law", material="melt_gamma0"),
        _p("a", "a", "-", 1.0, "first-order volume coefficient of the melt law", material="melt_a"),
    ),
    SteinbergGuinan, steinberg_guinan_flow_stress, steinberg_guinan_shear_modulus,
    constraints=(("G0_GPa > 0", lambda v: v["G0_GPa"] > 0),
                 ("Ymax_GPa >= Y0_GPa", lambda v: v["Ymax_GPa"] >= v["Y0_GPa"]),
                 ("beta >= 0 and eps_i >= 0", lambda v: v["beta"] >= 0 and v["eps_i"] >= 0)),
    melt_temperature=steinberg_guinan_melt_temperature,
    flow_stress_at=steinberg_guinan_flow_stress_at, hardening=steinberg_guinan_hardening,
    flow_stress_floor=steinberg_guinan_flow_stress_floor, rate_dependent=False,
)

PRESTON_TONKS_WALLACE = Law(
    "ptw", "Preston-Tonks-Wallace (2003), G = G0 (1 - alpha T / T_melt)",
    "Preston, Tonks & Wallace, J. Appl. Phys. 93, 211 (2003)",
    (
        _one("theta", "initial hardening rate (over G)"),
        _one("p", "hardening-law shape"),
        _one("s0", "saturation stress at 0 K (over G)"),
        _one("sinf", "saturation stress at high T (over G)"),
        _one("kappa", "temperature dependence of the thermal branch"),
        _one("gamma", "strain-rate scale of the thermal branch"),
        _one("y0", "yield stress at 0 K (over G)"),
        _one("yinf", "yield stress at high T (over G)"),
        _one("y1", "overdriven yield coefficient"),
        _one("y2", "overdriven yield exponent"),
        _one("beta", "overdriven saturation exponent"),
        _p("M_g_per_mol", "M", "g/mol", 1.0, "molar mass", material="molar_mass_g_per_mol"),
        _p("rho0_g_per_cc", "rho0", "g/cc", 1.0, "reference density", material="rho0_g_cc"),
        _gpa("G0_GPa", "G0", "shear modulus at 0 K"),
        _one("alpha", "linear thermal softening of G"),
        _p("T_melt_K", "T_melt", "K", 1.0, "melt temperature", material="T_melt_K"),
    ),
    PrestonTonksWallace, ptw_flow_stress, ptw_shear_modulus,
    constraints=(  # PTW 2003 sec. II (also lanl/impala's PTW_goodparam): yield below saturation, both falling with T
        ("sinf < s0", lambda v: v["sinf"] < v["s0"]), ("yinf < y0", lambda v: v["yinf"] < v["y0"]),
        ("y0 < s0", lambda v: v["y0"] < v["s0"]), ("yinf < sinf", lambda v: v["yinf"] < v["sinf"]),
        ("y1 > s0", lambda v: v["y1"] > v["s0"]), ("y2 > beta", lambda v: v["y2"] > v["beta"]),
        ("p >= 0, gamma > 0, G0_GPa > 0, M_g_per_mol > 0, rho0_g_per_cc > 0",
         lambda v: min(v["gamma"], v["G0_GPa"], v["M_g_per_mol"], v["rho0_g_per_cc"]) > 0 and v["p"] >= 0),
    ),
    melt_temperature=lambda law, eta: law.T_melt,
    flow_stress_at=ptw_flow_stress_at, hardening=ptw_hardening, flow_stress_floor=ptw_flow_stress_floor,
)

ZERILLI_ARMSTRONG = Law(
    "zerilli-armstrong", "Zerilli-Armstrong fcc (1987)", "Zerilli & Armstrong, J. Appl. Phys. 61, 1816 (1987)",
    (
        _mpa("C0_MPa", "C0", "athermal plus grain-size stress"),
        _mpa("C2_MPa", "C2", "hardening amplitude"),
        _p("C3_per_K", "C3", "1/K", 1.0, "thermal softening"),
        _p("C4_per_K", "C4", "1/K", 1.0, "thermal rate sensitivity"),
        _p("rate_ref_per_s", "rate_ref", "1/s", PER_S_TO_PER_US, "reference strain rate (1 /s: the paper's ln(epsdot))",
           1.0),
    ),
    ZerilliArmstrong, zerilli_armstrong_flow_stress,
    constraints=(("rate_ref_per_s > 0", lambda v: v["rate_ref_per_s"] > 0),),
    flow_stress_floor=zerilli_armstrong_flow_stress_floor, plastic_increment=zerilli_armstrong_plastic_increment,
)

LAWS: dict[str, Law] = {law.name: law for law in (JOHNSON_COOK, STEINBERG_GUINAN, PRESTON_TONKS_WALLACE,
                                                  ZERILLI_ARMSTRONG)}
DEFAULT_MODEL = JOHNSON_COOK.name    # the law of a study config without `strength.model`, and of `ShotParameters`
# its design columns (`Law.calibrated_columns`): the inputs of a config without `strength`, the default of a shot's
# and a candidate's strength inputs, and the columns no design may make negative (ShotParameters' rule)
DEFAULT_COLUMNS = tuple(JOHNSON_COOK.calibrated_columns())
ALIASES = {"jc": "johnson-cook", "sg": "steinberg-guinan", "preston-tonks-wallace": "ptw", "za": "zerilli-armstrong"}
