"""The hydrocode's inputs in user units: the shot's geometry, the material, the numerics.

These are what `run_shot` takes; each converts itself to the kernel's named tuples in code units
(cm, us, g/cc, Mbar). Field names are the study config's keys (`material`, `hydro`), so
`shockcal.study.adapters.hydro_inputs` builds them from a validated config by name alone.
"""

from __future__ import annotations

import math

from pydantic import model_validator

from shockcal.errors import InputError
from shockcal.hydro.eos import bulk_sound_speed_sq, zero_pressure_compression
from shockcal.hydro.rules import melting_problem, plate_problem
from shockcal.hydro.settings_model import SettingsModel, setting
from shockcal.hydro.state import InitialState, Material, Numerics
from shockcal.settings_model import SettingsError, section_fields
from shockcal.units import CM_US_TO_M_S, J_PER_KG_TO_CODE, MM_TO_CM, NS_TO_US, PER_S_TO_PER_US, UM_TO_CM

EOS = "material.eos"      # the config section of the equation of state's coefficients (MaterialProperties)


class Plates(SettingsModel):
    """A symmetric shot's plates: the study config's `shots.<shot>` section's keys that the hydrocode reads (the
    section's other keys map the design's inputs onto the shot and set its analysis window). Each field's rule
    and description is here once; the config schema's entries are generated from them. Checked on creation: a
    SettingsError (an InputError) naming the class and the field."""

    flyer_mm: float = setting(..., "Flyer plate thickness.", "positive")
    target_mm: float = setting(..., "Target plate thickness (the VISAR measures the velocity of its free surface).",
                               "positive")
    initial_temperature_K: float | None = setting(
        None, "Temperature of both plates before impact, below material.T_melt_K. Left out: the material's T_ref_K "
              "(a room-temperature shot). Hotter plates start at rest and zero pressure, expanded as the EOS says "
              "(E0 = cv (T0 - T_ref), density from P(rho, E0) = 0), and Johnson-Cook softened by their T*. flyer_mm "
              "and target_mm are then the hot thicknesses (docs/hydro.md, \"Initial temperature\").", "positive",
        optional=True)


class Geometry(Plates):
    """A symmetric plate impact, its plates (`Plates`) and how long to run it; checked on creation (an InputError
    naming the field). None of these three fields is a config key: the study sets them from `hydro.end_time_us`
    and the shot's analysis window (`shockcal.study.adapters.hydro_inputs`).

        Geometry(flyer_mm=3.95, target_mm=5.965, end_us=2.2)
    """

    end_us: float = setting(..., "Simulated time after impact (us).", "positive")
    stop_after_rise_us: float | None = setting(
        None, "End the run this long (us) after its free-surface velocity first exceeds rise_fraction x its impact "
              "velocity, or at end_us if sooner; None: at end_us.", "positive")
    rise_fraction: float | None = setting(None, "That share of the impact velocity (-), with stop_after_rise_us.",
                                          "positive")

    @model_validator(mode="after")
    def _stop_both_or_neither(self):
        if (self.stop_after_rise_us is None) != (self.rise_fraction is None):
            raise InputError("Geometry.stop_after_rise_us and Geometry.rise_fraction: give both or neither")
        return self


class MaterialProperties(SettingsModel):
    """Mie-Grueneisen EOS (cubic cold curve in mu = rho/rho0 - 1) and thermal constants of flyer and target: the
    study config's `material` section once resolved (its library entry filled in, its EOS as the cubic:
    `shockcal.hydro.material_library.material_properties(section)`, `load_material("copper")`). Each field's
    rule, default and description is here once; the config schema's `material` and `material.eos` entries are
    generated from them. Checked on creation: an InputError naming the field. A field left None is not given (a
    law that needs it is refused, naming it).
    """

    rho0_g_cc: float = setting(..., "Initial density.", "positive")
    c1_Mbar: float = setting(
        ..., "Cubic form: linear coefficient c1 (the bulk modulus; the bulk sound speed is sqrt(c1 / rho0)); "
             "c1_Mbar, c2_Mbar, c3_Mbar are required unless c0_km_s and s are given.", "positive", section=EOS)
    c2_Mbar: float = setting(..., "Cubic form: quadratic coefficient c2.", "finite", section=EOS)
    c3_Mbar: float = setting(..., "Cubic form: cubic coefficient c3.", "finite", section=EOS)
    gamma0: float = setting(..., "Grueneisen coefficient gamma0 (dimensionless); in both forms.", "nonnegative",
                            section=EOS)
    T_ref_K: float = setting(..., "Reference (room) temperature, where Johnson-Cook thermal softening starts "
                                  "(T* = 0).", "positive")
    T_melt_K: float = setting(..., "Melting temperature, where the flow stress vanishes (T* = 1); above T_ref_K.",
                              "positive")
    cv_J_per_kg_K: float = setting(..., "Specific heat at constant volume (temperature from internal energy).",
                                   "positive")
    strain_rate_ref_per_s: float = setting(
        1.0, "Johnson-Cook reference strain rate epsdot_0: the rate factor is 1 + C ln(epsdot / epsdot_0), "
             "floored at 1.", "positive")
    molar_mass_g_per_mol: float | None = setting(
        None, "Molar mass (an alloy's mean atomic mass), PTW's M in its strain-rate scale. Left out (and not in the "
              "library entry): a ptw study stops naming this key. Only a study whose law reads it slices it into "
              "its simulate (and yield-input emulate) jobs (shockcal.study.stages), so it reruns no other law's.",
        "positive", optional=True)
    melt_T_m0_K: float | None = setting(
        None, "Steinberg's melt law T_m = T_m0 exp(2a (1 - 1/eta)) eta^(2 (gamma0 - a - 1/3)), Steinberg-Guinan's "
              "melting temperature: T_m0, at eta = rho/rho0 = 1. Left out (and not in the library entry): a "
              "steinberg-guinan study stops naming this key. Like melt_gamma0 and melt_a, sliced into the "
              "simulate jobs of a steinberg-guinan study only (shockcal.study.stages).", "positive", optional=True)
    melt_gamma0: float | None = setting(
        None, "Steinberg's melt law: its Grueneisen coefficient gamma0 (dimensionless; Steinberg's table value, not "
              "necessarily eos.gamma0). Left out: a steinberg-guinan study stops naming this key.", "nonnegative",
        optional=True)
    melt_a: float | None = setting(
        None, "Steinberg's melt law: its first-order volume coefficient a (dimensionless). Left out: a "
              "steinberg-guinan study stops naming this key.", "finite", optional=True)

    @model_validator(mode="after")
    def _melting_above_reference(self):
        problem = melting_problem(self.T_ref_K, self.T_melt_K)
        if problem:
            raise SettingsError(f"MaterialProperties.T_melt_K: {problem}", "T_melt_K", problem)
        return self

    @classmethod
    def from_section(cls, values: dict, **more):
        """From a resolved `material` section (`shockcal.hydro.material_library.resolve_material`): its own keys
        and its `eos` mapping's."""
        eos = values.get("eos") if isinstance(values.get("eos"), dict) else {}
        return super().from_section(values, **{name: eos[name] for name in section_fields(cls, EOS) if name in eos},
                                    **more)

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
