"""The hydrocode's state and parameters as named tuples in code units (cm, us, g/cc, Mbar), the kernels' currency.

`Material`, `InitialState`, `LawStrength` (any law, Johnson-Cook included) and `Numerics` are what a run
hands the kernels (`shockcal.hydro.settings` builds them from user units); `Nodes` and `Cells` are the mesh's
state (drawn in `shockcal.hydro.solver`); `KernelResult` is what `solver.simulate` returns, with a status code
and its reason (`FAILURE_REASONS`).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

STATUS_OK, STATUS_NEGATIVE_VOLUME, STATUS_NAN, STATUS_DT_COLLAPSE = 0, 1, 2, 3
FAILURE_REASONS = {STATUS_NEGATIVE_VOLUME: "negative cell volume", STATUS_NAN: "NaN in cell state",
                   STATUS_DT_COLLAPSE: "time step collapsed"}


class Material(NamedTuple):
    """Flyer and target material: Mie-Grueneisen EOS and thermal constants (code units)."""

    rho0: float            # g/cc
    c1: float              # Mbar
    c2: float              # Mbar
    c3: float              # Mbar
    gamma0: float
    T_ref: float           # K
    T_melt: float          # K
    cv: float              # (cm/us)^2 / K


class InitialState(NamedTuple):
    """Both plates before impact: at rest, at zero pressure, at the shot's initial temperature (code
    units). At T_ref: rho = rho0, E = 0; hotter, E = cv (T0 - T_ref) and rho solves P(rho, E) = 0
    (`MaterialProperties.initial_state`)."""

    rho: float             # g/cc
    E: float               # specific internal energy, (cm/us)^2


class LawStrength(NamedTuple):
    """Any strength law of `shockcal.hydro.laws` in one run: its named tuple in code units and the
    shot's shear modulus G (Mbar), used only by laws without a shear-modulus law of their own
    (Johnson-Cook, Zerilli-Armstrong). numba compiles the kernels once per law tuple type."""

    law: tuple
    G: float


class Numerics(NamedTuple):
    """Artificial viscosity and time stepping (us)."""

    q1: float
    q2: float
    cfl: float
    dt_initial: float
    dt_max: float


class KernelResult(NamedTuple):
    """What `simulate` returns (code units: cm/us, Mbar cm, us, K)."""

    v_free_surface: np.ndarray   # target's free-surface velocity at t_out, cm/us
    energy: np.ndarray           # total energy per unit area at t_out (zero past a failure), Mbar cm
    status: int                  # STATUS_OK or a failure code (FAILURE_REASONS)
    fail_cell: int               # the failed cell, or -1
    fail_time: float             # us
    n_steps: int
    max_plastic_rate: float      # 1/us, over the target's cells
    max_temperature: float       # K
    max_plastic_strain: float
    n_out: int                   # outputs the run was to reach: len(t_out), or fewer once it ended after the rise


class Nodes(NamedTuple):
    """Node velocity (cm/us) and lumped mass per unit area (g/cm^2), nodes 0..N+1."""

    u: np.ndarray
    mass: np.ndarray


class Cells(NamedTuple):
    """Cell state, cells 0..N (cell `gap` is the contact gap: no mass, its length is the gap).

    `hard` holds the law's cached hardening and the three floor slots (`flow_floor`, `floor_hotter`,
    `floor_T`) the floor the law remembers, in the law's meaning (`plastic_return.plastic_return`;
    Johnson-Cook: the thermal factor 1 - T*^m at floor_T, K, and a lower bound of it
    `laws.johnson_cook.FLOOR_MARGIN_K` hotter; PTW: tau^, the sixth power of the lowest rate ratio and the
    highest temperature it holds for). A trial stress inside the floor is elastic without evaluating the law.
    `power_T`, `power`, `x_warm` and `rate_warm` are what a cell that stays plastic reuses, in the law's meaning
    (Johnson-Cook: T*^m at power_T, K, and the solve's x = ln(rate / epsdot_0) and the plastic rate, 1/us, of
    the cell's last plastic step; power = 0 and rate_warm = 0: none yet; `shockcal.hydro.series`)."""

    mass: np.ndarray       # g/cm^2
    length: np.ndarray     # cm
    E: np.ndarray          # specific internal energy, (cm/us)^2
    P: np.ndarray          # pressure, Mbar
    s: np.ndarray          # deviator s_xx, Mbar
    sigma: np.ndarray      # total stress -(P + q) + s, Mbar
    eps_p: np.ndarray      # equivalent plastic strain
    hard: np.ndarray       # the law's cached hardening (laws.kernels.law_hardening; Johnson-Cook: A + B eps_p^n, Mbar)
    flow_floor: np.ndarray  # Mbar
    floor_hotter: np.ndarray  # Mbar
    floor_T: np.ndarray    # K
    power_T: np.ndarray    # K
    power: np.ndarray      # -
    x_warm: np.ndarray     # -
    rate_warm: np.ndarray  # 1/us
