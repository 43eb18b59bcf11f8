"""The hydrocode's inputs in user units: the shot's geometry, the material, the numerics.

These are what `run_shot` takes; each converts itself to the kernel's named tuples in code units
(cm, us, g/cc, Mbar). Field names are the study config's keys (`material`, `hydro`), so
`shockcal.study.adapters.hydro_inputs` builds them from a validated config by name alone.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from shockcal.errors import InputError
from shockcal.hydro.eos import bulk_sound_speed_sq, zero_pressure_compression
from shockcal.hydro.rules import check_fields, melting_problem, plate_problem
from shockcal.hydro.settings_model import SettingsModel, setting
from shockcal.hydro.state import InitialState, Material, Numerics
from shockcal.units import CM_US_TO_M_S, J_PER_KG_TO_CODE, MM_TO_CM, NS_TO_US, PER_S_TO_PER_US, UM_TO_CM


@dataclass(frozen=True)
class Geometry:
    """A symmetric plate impact; checked on creation (`shockcal.hydro.rules`: an InputError naming the field).

    Args:
        flyer_mm: flyer plate thickness (mm), at the shot's initial temperature (the hot thickness of a
            heated shot).
        target_mm: target plate thickness (mm), likewise; the measured free surface is its back.
        end_us: simulated time after impact (us).
        initial_temperature_K: temperature of both plates before impact (K); None: the material's
            T_ref_K (a room-temperature shot). Hotter plates start expanded, at zero pressure
            (`MaterialProperties.initial_state`).
        stop_after_rise_us: end the run this long (us) after its free-surface velocity first exceeds
            `rise_fraction` x its impact velocity, or at end_us if sooner; None: at end_us.
        rise_fraction: that share of the impact velocity (-), with stop_after_rise_us.
    """

    flyer_mm: float
    target_mm: float
    end_us: float
    initial_temperature_K: float | None = None
    stop_after_rise_us: float | None = None
    rise_fraction: float | None = None

    def __post_init__(self):
        check_fields(self, {"flyer_mm": "positive", "target_mm": "positive", "end_us": "positive",
                            "initial_temperature_K": "positive", "stop_after_rise_us": "positive",
                            "rise_fraction": "positive"})
        if (self.stop_after_rise_us is None) != (self.rise_fraction is None):
            raise InputError("Geometry.stop_after_rise_us and Geometry.rise_fraction: give both or neither")


@dataclass(frozen=True)
class MaterialProperties:
    """Mie-Grueneisen EOS (cubic cold curve in mu = rho/rho0 - 1) and thermal constants of flyer and target;
    checked on creation (`shockcal.hydro.rules`: an InputError naming the field). From a library name or
    the Us-up Hugoniot (c0, s, gamma0): `shockcal.hydro.material_library.load_material("copper")`,
    `shockcal.hydro.material_library.material_properties(section)` (the study config's `material` rules).

    Args:
        rho0_g_cc: initial density (g/cc).
        c1_Mbar, c2_Mbar, c3_Mbar: cold-curve coefficients P = c1 mu + c2 mu^2 + c3 mu^3 (Mbar).
        gamma0: Grueneisen parameter (-); gamma0 rho0 is held constant.
        T_ref_K: reference (room) temperature (K), where T* = 0.
        T_melt_K: melting temperature (K), where T* = 1 and the strength vanishes.
        cv_J_per_kg_K: specific heat (J/kg/K).
        strain_rate_ref_per_s: the Johnson-Cook reference strain rate eps0 (1/s).
        molar_mass_g_per_mol: molar mass (g/mol; an alloy's mean atomic mass), which PTW's strain-rate
            scale reads; None: not given (a law that needs it is refused, naming it).
        melt_T_m0_K, melt_gamma0, melt_a: Steinberg's melt law T_m = T_m0 exp(2a(1 - 1/eta))
            eta^(2(gamma0 - a - 1/3)) (Steinberg-Guinan's): melt temperature at eta = 1 (K), its Grueneisen
            coefficient and first-order volume coefficient (-); None: not given.
    """

    rho0_g_cc: float
    c1_Mbar: float
    c2_Mbar: float
    c3_Mbar: float
    gamma0: float
    T_ref_K: float
    T_melt_K: float
    cv_J_per_kg_K: float
    strain_rate_ref_per_s: float = 1.0
    molar_mass_g_per_mol: float | None = None
    melt_T_m0_K: float | None = None
    melt_gamma0: float | None = None
    melt_a: float | None = None

    def __post_init__(self):
        check_fields(self, {"rho0_g_cc": "positive", "c1_Mbar": "positive", "c2_Mbar": "finite", "c3_Mbar": "finite",
                            "gamma0": "nonnegative", "T_ref_K": "positive", "T_melt_K": "positive",
                            "cv_J_per_kg_K": "positive", "strain_rate_ref_per_s": "positive",
                            "molar_mass_g_per_mol": "positive", "melt_T_m0_K": "positive",
                            "melt_gamma0": "nonnegative", "melt_a": "finite"})
        problem = melting_problem(self.T_ref_K, self.T_melt_K)
        if problem:
            raise InputError(f"MaterialProperties: {problem}")

    def code_units(self) -> Material:
        return Material(self.rho0_g_cc, self.c1_Mbar, self.c2_Mbar, self.c3_Mbar, self.gamma0, self.T_ref_K,
                        self.T_melt_K, self.cv_J_per_kg_K * J_PER_KG_TO_CODE)

    def rate_ref_per_us(self) -> float:
        return self.strain_rate_ref_per_s * PER_S_TO_PER_US

    def initial_state(self, temperature_K: float | None = None) -> InitialState:
        """The material at rest and zero pressure at `temperature_K` (K; None: T_ref_K), in code units:
        E0 = cv (T0 - T_ref) (the code's T = T_ref + E / cv), rho = rho0 (1 + mu0) with mu0 the root of
        c1 mu0 + c2 mu0^2 + c3 mu0^3 + gamma0 rho0 E0 = 0 (`eos.zero_pressure_compression`). At T_ref
        exactly: rho0 and E0 = 0, bit for bit."""
        T0 = self.T_ref_K if temperature_K is None else float(temperature_K)
        E0 = self.cv_J_per_kg_K * J_PER_KG_TO_CODE * (T0 - self.T_ref_K)
        mu0 = zero_pressure_compression(E0, self.rho0_g_cc, self.c1_Mbar, self.c2_Mbar, self.c3_Mbar, self.gamma0)
        return InitialState(self.rho0_g_cc * (1.0 + mu0), E0)

    def initial_density_g_cc(self, temperature_K: float | None = None) -> float:
        """Density at rest and zero pressure at `temperature_K` (K; None: T_ref_K), g/cc."""
        return self.initial_state(temperature_K).rho

    def bulk_sound_speed_m_s(self, temperature_K: float | None = None) -> float:
        """Bulk sound speed sqrt((dP/drho)_s) of this EOS at rest and zero pressure at `temperature_K`
        (K; None: T_ref_K), m/s."""
        mu0 = self.initial_state(temperature_K).rho / self.rho0_g_cc - 1.0
        c_sq = bulk_sound_speed_sq(mu0, 0.0, 1.0, self.rho0_g_cc, self.c1_Mbar, self.c2_Mbar, self.c3_Mbar,
                                   self.gamma0)
        return math.sqrt(c_sq) * CM_US_TO_M_S


class HydroSettings(SettingsModel):
    """Mesh, output sampling, artificial viscosity and time stepping: the study config's `hydro` section
    (its other key, `end_time_us`, is the Geometry's end_us). Each field's default, rule and description is
    here once; the config schema's entries are generated from them (`shockcal.hydro.settings_model`) and
    docs/hydro.md measures the defaults. Checked on creation: an InputError naming the field."""

    cell_size_um: float = setting(4.0, "Mesh cell size in both plates.", "positive")
    output_dt_ns: float = setting(0.5, "Sampling interval of the free-surface velocity trace written per run.",
                                  "positive")
    cfl: float = setting(0.5, "CFL number of the time step, on the longitudinal sound speed with the viscous "
                              "signal speed.", "courant")
    dt_initial_us: float = setting(1.0e-7, "First time step; the step then grows by at most 10% a step.", "positive")
    dt_max_us: float = setting(2.0e-3, "Largest time step.", "positive")
    q_linear: float = setting(0.1, "Linear artificial-viscosity coefficient q1 (dimensionless): q = rho (q2 du^2 - "
                                   "q1 c_L du) in compression.", "nonnegative")
    q_quadratic: float = setting(1.0, "Quadratic artificial-viscosity coefficient q2 (dimensionless).", "nonnegative")

    def numerics(self) -> Numerics:
        return Numerics(self.q_linear, self.q_quadratic, self.cfl, self.dt_initial_us, self.dt_max_us)

    def cells(self, thickness_mm: float, plate: str = "plate") -> int:
        """Cells across a plate of `thickness_mm` (mm); an InputError naming `plate` when it is thinner than
        one cell (`shockcal.hydro.rules.plate_problem`)."""
        problem = plate_problem(thickness_mm, self.cell_size_um)
        if problem:
            raise InputError(f"{plate}: {problem}")
        return int(round(thickness_mm * MM_TO_CM / (self.cell_size_um * UM_TO_CM)))

    def output_dt_us(self) -> float:
        return self.output_dt_ns * NS_TO_US
