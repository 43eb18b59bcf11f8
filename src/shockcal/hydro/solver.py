"""Staggered-grid 1D Lagrangian solver for a flyer plate striking a target (uniaxial strain).

Units inside: cm, us, g/cc, Mbar (1 Mbar = 1 g/cc (cm/us)^2); specific energy in (cm/us)^2.

Mesh (`Nodes`, `Cells`): nodes 0..N+1, cells 0..N (N = nf + nt), cell j between nodes j and j+1:

       flyer (moving at the impact velocity)           gap          target (at rest)
    |-------|-------| ... |-------|               |--------|------| ... |-------|
    0  c0   1  c1   2      nf-1   nf     c_nf     nf+1  c_nf+1          N  c_N  N+1
    ^ free surface (flyer's back)    contact gap:            measured free surface ^ u[N+1]
                                     no mass, no stress,
                                     length = the gap (0 at impact)

    node i:  velocity u, lumped mass (half of each neighbouring cell's)       (`Nodes`)
    cell j:  length, E, P, deviator s, sigma = -(P + q) + s, eps_p, floors    (`Cells`)
    q, the artificial viscosity, is computed per cell and step and lives only in sigma.

The flyer's cells are 0..nf-1, the target's nf+1..N; cell nf is the contact gap between the flyer's
rear node nf and the target's front node nf+1. Both outer nodes are free surfaces. Each step
(leapfrog), one kernel per line:
1. `accelerate_nodes`: u += dt (sigma_right - sigma_left) / m_node, sigma = -(P + q) + s;
2. `close_contact`: if the gap would close, the two interface nodes take their common momentum
   velocity and the energy an impact dissipates goes to the interface cells; under tension the
   nodes separate, which opens the interface;
3. `update_cells`: length from the node velocities, strain rate, artificial viscosity (compression
   only), the cell's shear modulus, elastic trial deviator and radial return onto the strength law
   (`plastic_return`: Johnson-Cook's skipped while the trial lies inside the cell's flow-stress floor,
   `floor_at`, `new_floors`; any other law's evaluated every step), energy equation, EOS;
4. time step: CFL on the longitudinal sound speed, viscosity included (`signal_speed`), growth
   limited to 10%.
The material, strength and numerics parameters travel as named tuples in code units
(`Material`, `Strength` for Johnson-Cook or `LawStrength` for any law, `Numerics`; `shockcal.units`
converts); numba compiles the kernels once per strength tuple type. Kernels that loop over the mesh
take its arrays out of `Nodes` / `Cells` once: a field read per cell would cost a reference count.
Only the region the waves have reached is updated: an undisturbed cell has exactly zero stress,
so its nodes keep their initial velocities bit for bit, and the active window grows by one node
when the stress of the cell beyond it becomes non-zero. (In a hot shot a cell at rest evaluates its
EOS to a rounding residual, |P| < 1e-15 Mbar, so the window may run ahead of the wave: the same
physics, a little more work.)
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit
from numba.extending import overload

from shockcal.hydro.eos import bulk_sound_speed_sq, cold_pressure
from shockcal.hydro.laws.kernels import law_flow_stress, law_shear_modulus
from shockcal.hydro.strength import (
    equivalent_strain_rate,
    flow_stress,
    hardening,
    radial_return,
    rate_factor,
    thermal_factor,
    thermal_factor_below,
)

STATUS_OK, STATUS_NEGATIVE_VOLUME, STATUS_NAN, STATUS_DT_COLLAPSE = 0, 1, 2, 3
FAILURE_REASONS = {STATUS_NEGATIVE_VOLUME: "negative cell volume", STATUS_NAN: "NaN in cell state",
                   STATUS_DT_COLLAPSE: "time step collapsed"}
DT_FLOOR_US = 1.0e-12
FLOOR_MARGIN_K = 1.0       # a cell's flow-stress floor holds up to this much above the temperature it was set at
FLOOR_SLACK = 1.0 - 1e-12  # keeps the floor below the flow stress through rounding (products in another order)
DT_GROWTH = 1.1            # the time step grows by at most 10% a step


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


class Strength(NamedTuple):
    """Shear modulus and Johnson-Cook parameters of one run (Mbar, -, 1/us)."""

    G: float
    A: float
    B: float
    C: float
    n: float
    m: float
    rate_ref: float


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


class Nodes(NamedTuple):
    """Node velocity (cm/us) and lumped mass per unit area (g/cm^2), nodes 0..N+1."""

    u: np.ndarray
    mass: np.ndarray


class Cells(NamedTuple):
    """Cell state, cells 0..N (cell `gap` is the contact gap: no mass, its length is the gap).

    `flow_floor` is a lower bound of the cell's rate-free flow stress (A + B eps_p^n)(1 - T*^m),
    valid while its temperature stays at or below `floor_T`, the temperature of its last full
    evaluation (the thermal factor falls with T, the hardening grows with eps_p); `floor_hotter`
    is one valid up to `FLOOR_MARGIN_K` above it (`strength.thermal_factor_below`, no extra pow),
    so that a slowly heating cell keeps a floor. A trial stress inside a floor is elastic without
    a pow or log; inside the floor times the rate factor (one log), elastic without a pow. `hard` and
    the floors are Johnson-Cook's (`Strength`); under `LawStrength` they stay unused."""

    mass: np.ndarray       # g/cm^2
    length: np.ndarray     # cm
    E: np.ndarray          # specific internal energy, (cm/us)^2
    P: np.ndarray          # pressure, Mbar
    s: np.ndarray          # deviator s_xx, Mbar
    sigma: np.ndarray      # total stress -(P + q) + s, Mbar
    eps_p: np.ndarray      # equivalent plastic strain
    hard: np.ndarray       # A + B eps_p^n, Mbar
    flow_floor: np.ndarray  # Mbar
    floor_hotter: np.ndarray  # Mbar
    floor_T: np.ndarray    # K


@njit(cache=True, error_model="numpy")
def initial_mesh(nf, nt, dx, velocity, initial, strength, material):
    """Flyer (cells 0..nf-1) at `velocity` against a target at rest (cells nf+1..N), touching; every
    cell of length dx at the initial state's density and energy, at zero pressure and stress."""
    N = nf + nt
    gap = nf
    mass = np.full(N + 1, initial.rho * dx)
    mass[gap] = 0.0
    length = np.full(N + 1, dx)
    length[gap] = 0.0
    E = np.full(N + 1, initial.E)
    E[gap] = 0.0
    hard = np.full(N + 1, initial_hardening(strength))
    cells = Cells(mass, length, E, np.zeros(N + 1), np.zeros(N + 1), np.zeros(N + 1),
                  np.zeros(N + 1), hard, np.zeros(N + 1), np.zeros(N + 1), np.full(N + 1, np.inf))
    u = np.zeros(N + 2)
    u[: nf + 1] = velocity
    node_mass = np.empty(N + 2)
    node_mass[0] = 0.5 * mass[0]
    for i in range(1, N + 1):
        node_mass[i] = 0.5 * (mass[i - 1] + mass[i])
    node_mass[N + 1] = 0.5 * mass[N]
    return Nodes(u, node_mass), cells


@njit(cache=True, error_model="numpy")
def total_energy(nodes, cells):
    """Kinetic + internal energy per unit area (Mbar cm)."""
    u, node_mass, E, cell_mass = nodes.u, nodes.mass, cells.E, cells.mass
    kinetic = 0.0
    for i in range(u.shape[0]):
        kinetic += 0.5 * node_mass[i] * u[i] * u[i]
    internal = 0.0
    for j in range(E.shape[0]):
        internal += cell_mass[j] * E[j]
    return kinetic + internal


@njit(cache=True, error_model="numpy")
def accelerate_nodes(nodes, sigma, lo, hi, dt):
    """Momentum: u += dt (sigma_right - sigma_left) / m_node; outside the mesh the stress is 0."""
    u, node_mass = nodes.u, nodes.mass
    N = sigma.shape[0] - 1
    for i in range(lo, hi + 1):
        left = sigma[i - 1] if i > 0 else 0.0
        right = sigma[i] if i <= N else 0.0
        u[i] += dt * (right - left) / node_mass[i]


@njit(cache=True, error_model="numpy")
def close_contact(nodes, cells, gap, dt, approach_speed, g_rho0):
    """The gap's length from its nodes' velocities. If it would close, the interface nodes move
    together (momentum conserved); an impact (nodes that approached at `approach_speed` before
    this step) dissipates 0.5 mu approach_speed^2, which goes into the two interface cells as a
    shock would put it. Nodes already moving together lose nothing: merging them is the combined
    node's momentum update. Under tension the nodes separate and the gap opens."""
    u, m = nodes.u, nodes.mass
    a, b = gap, gap + 1
    if cells.length[gap] + dt * (u[b] - u[a]) <= 0.0:
        common = (m[a] * u[a] + m[b] * u[b]) / (m[a] + m[b])
        u[a] = common
        u[b] = common
        reduced_mass = m[a] * m[b] / (m[a] + m[b])
        dissipated = 0.5 * reduced_mass * approach_speed * approach_speed
        for j in (gap - 1, gap + 1):
            dE = 0.5 * dissipated / cells.mass[j]
            cells.E[j] += dE
            cells.P[j] += g_rho0 * dE
            cells.sigma[j] -= g_rho0 * dE
    cells.length[gap] = max(cells.length[gap] + dt * (u[b] - u[a]), 0.0)


@njit(cache=True, error_model="numpy")
def artificial_viscosity(du, volume, c_long, q1, q2):
    """q = (q2 du^2 - q1 c_L du) / V in compression (du < 0), else 0 (Mbar)."""
    return (q2 * du * du - q1 * c_long * du) / volume if du < 0.0 else 0.0


@njit(cache=True, error_model="numpy")
def signal_speed(du, c_long, q1, q2):
    """The CFL signal speed: a + sqrt(a^2 + c_L^2), a = q1 c_L + 2 q2 |du| the viscous speed in
    compression; c_L otherwise (cm/us)."""
    if du < 0.0:
        a_visc = q1 * c_long + 2.0 * q2 * abs(du)
        return a_visc + math.sqrt(a_visc * a_visc + c_long * c_long)
    return c_long


@njit(cache=True, error_model="numpy")
def homologous_temperature(T, material):
    """T* = (T - T_ref) / (T_melt - T_ref)."""
    return (T - material.T_ref) * (1.0 / (material.T_melt - material.T_ref))


@njit(cache=True, error_model="numpy")
def johnson_cook_return(s_trial, T_cell, strain_rate, hard, strength, material):
    """(s, d eps_p, thermal factor, a lower bound of it FLOOR_MARGIN_K hotter): the trial deviator
    returned onto the Johnson-Cook yield surface at the cell's temperature (K) and current strain
    rate (1/us) if outside it, and the thermal factors of the cell's floors."""
    homologous = homologous_temperature(T_cell, material)
    thermal = thermal_factor(strength.m, homologous)
    s_new, d_eps = radial_return(s_trial, flow_stress(hard, thermal, strength.C, strain_rate, strength.rate_ref),
                                 strength.G)
    margin = FLOOR_MARGIN_K * (1.0 / (material.T_melt - material.T_ref))
    return s_new, d_eps, thermal, thermal_factor_below(strength.m, homologous, thermal, margin)


@njit(cache=True, error_model="numpy")
def floor_at(T_cell, flow_floor, floor_hotter, floor_T):
    """A cell's flow-stress floor (Mbar) at temperature T_cell (K), from its cached floors: the one set at
    floor_T (K) while the cell is no hotter, the hotter one up to FLOOR_MARGIN_K above it, else -1 (none)."""
    if T_cell <= floor_T:
        return flow_floor
    if T_cell <= floor_T + FLOOR_MARGIN_K:
        return floor_hotter
    return -1.0


@njit(cache=True, error_model="numpy")
def new_floors(hard, thermal, thermal_hotter):
    """(flow_floor, floor_hotter) after a full evaluation of the flow stress: A + B eps_p^n (Mbar) times
    the thermal factor at the cell's temperature and its bound FLOOR_MARGIN_K hotter, each just below by
    FLOOR_SLACK."""
    return FLOOR_SLACK * hard * thermal, FLOOR_SLACK * hard * thermal_hotter


@njit(cache=True, error_model="numpy")
def inside_floor(equivalent_stress, flow_floor, strain_rate, strength):
    """Whether a trial von Mises stress is provably elastic: inside the rate-free floor, or (one log)
    inside the floor times the Johnson-Cook rate factor. A negative floor means none holds."""
    if equivalent_stress <= flow_floor:
        return True
    if flow_floor <= 0.0 or strength.C == 0.0:     # no floor, or no rate term to raise it
        return False
    return equivalent_stress <= flow_floor * rate_factor(strength.C, equivalent_strain_rate(strain_rate),
                                                         strength.rate_ref)


def johnson_cook_floored_return(s_trial, T_cell, strain_rate, P, eta, G, eps_p, hard, flow_floor, floor_hotter,
                                floor_T, strength, material):
    """Johnson-Cook (`Strength`): elastic without evaluating the flow stress while the trial lies inside
    the cell's floor, else the return at the cell's temperature (K) and current strain rate (1/us), with
    the cell's new plastic strain, hardening and floors."""
    floor = floor_at(T_cell, flow_floor, floor_hotter, floor_T)
    if inside_floor(1.5 * abs(s_trial), floor, strain_rate, strength):
        return s_trial, 0.0, eps_p, hard, flow_floor, floor_hotter, floor_T
    s_new, d_eps, thermal, thermal_hotter = johnson_cook_return(s_trial, T_cell, strain_rate, hard, strength, material)
    if d_eps > 0.0:
        eps_p += d_eps
        hard = hardening(strength.A, strength.B, strength.n, eps_p)
    flow_floor, floor_hotter = new_floors(hard, thermal, thermal_hotter)
    return s_new, d_eps, eps_p, hard, flow_floor, floor_hotter, T_cell


def law_return(s_trial, T_cell, strain_rate, P, eta, G, eps_p, hard, flow_floor, floor_hotter, floor_T, strength,
               material):
    """Any law (`LawStrength`): the trial returned onto the law's flow stress at the cell's plastic strain,
    equivalent strain rate (1/us), temperature (K), pressure (Mbar) and density ratio, evaluated every
    step (no floor; `hard` and the floors pass through), with the cell's shear modulus G (Mbar). A cell
    with G = 0 (molten) carries no deviator and gains no plastic strain."""
    if G <= 0.0:
        return 0.0, 0.0, eps_p, hard, flow_floor, floor_hotter, floor_T
    Y = law_flow_stress(strength.law, eps_p, equivalent_strain_rate(strain_rate), T_cell, P, eta)
    s_new, d_eps = radial_return(s_trial, Y, G)
    return s_new, d_eps, eps_p + d_eps, hard, flow_floor, floor_hotter, floor_T


def plastic_return(s_trial, T_cell, strain_rate, P, eta, G, eps_p, hard, flow_floor, floor_hotter, floor_T, strength,
                   material):
    """A cell's return after its elastic trial deviator s_trial (Mbar), on scalars: (s, d eps_p, and the
    cell's new eps_p, hard, flow_floor, floor_hotter, floor_T). `johnson_cook_floored_return` for
    `Strength`, `law_return` for `LawStrength`, chosen when numba compiles by the type of `strength`
    and inlined. Scalars in and out: inlined code that indexes the cell arrays cost the 104S run 23%
    more CPU (reference counts per cell)."""


def cell_shear_modulus(strength, P, T, eta):
    """The shear modulus (Mbar) of a cell at pressure P (Mbar), temperature T (K) and density ratio eta:
    the run's constant G, or the law's G(P, T, eta) for laws that have one (Steinberg-Guinan, PTW)."""


def initial_hardening(strength):
    """Johnson-Cook's A + B 0^n (Mbar), the cells' initial `hard`; 0 for `LawStrength` (unused)."""


def _is_johnson_cook(strength):
    return getattr(strength, "instance_class", None) is Strength


@overload(plastic_return, inline="always")
def _plastic_return(s_trial, T_cell, strain_rate, P, eta, G, eps_p, hard, flow_floor, floor_hotter, floor_T, strength,
                    material):
    return johnson_cook_floored_return if _is_johnson_cook(strength) else law_return


@overload(cell_shear_modulus, inline="always")
def _cell_shear_modulus(strength, P, T, eta):
    if _is_johnson_cook(strength):
        return lambda strength, P, T, eta: strength.G
    return lambda strength, P, T, eta: law_shear_modulus(strength.law, strength.G, P, T, eta)


@overload(initial_hardening, inline="always")
def _initial_hardening(strength):
    if _is_johnson_cook(strength):
        return lambda strength: hardening(strength.A, strength.B, strength.n, 0.0)
    return lambda strength: 0.0


@njit(cache=True, error_model="numpy")
def energy_update(E, P, p_cold, q, dV, work_dev, g_rho0):
    """dE = -(P + q) dV + deviatoric work, P trapezoid-implicit: P_new = p_cold + g_rho0 E_new."""
    return (E - (0.5 * (P + p_cold) + q) * dV + work_dev) / (1.0 + 0.5 * g_rho0 * dV)


@njit(cache=True, error_model="numpy")
def update_cells(nodes, cells, gap, lo, hi, dt, strength, material, numerics, peaks):
    """Advance the active cells (those touching nodes lo..hi, the gap excepted) by dt: length and
    strain rate from the node velocities, the cell's shear modulus, EOS sound speed, artificial
    viscosity, elastic trial and the law's return (`plastic_return`), energy and pressure. Returns
    (status, failed cell or -1, max CFL signal rate c / L (1/us), at least cfl / dt_max); a failed
    cell keeps its state. `peaks` holds the target's running maxima of plastic rate (1/us, a
    diagnostic only), temperature (K) and plastic strain."""
    u = nodes.u
    mass, length, E, P, s, sigma = cells.mass, cells.length, cells.E, cells.P, cells.s, cells.sigma
    eps_p, hard, flow_floor, floor_hotter, floor_T = (cells.eps_p, cells.hard, cells.flow_floor, cells.floor_hotter,
                                                      cells.floor_T)
    N = E.shape[0] - 1
    g_rho0 = material.gamma0 * material.rho0
    max_signal_rate = numerics.cfl / numerics.dt_max
    for j in range(max(lo - 1, 0), min(hi, N) + 1):
        if j == gap:
            continue
        du = u[j + 1] - u[j]
        new_length = length[j] + dt * du
        if not new_length > 0.0:
            return STATUS_NEGATIVE_VOLUME, j, max_signal_rate
        strain_rate = 2.0 * du / (length[j] + new_length)
        volume = new_length / mass[j]              # specific volume 1/rho
        eta = 1.0 / (material.rho0 * volume)       # rho / rho0
        mu = eta - 1.0
        T_cell = material.T_ref + E[j] / material.cv
        G = cell_shear_modulus(strength, P[j], T_cell, eta)
        four_thirds_G = 4.0 * G / 3.0
        c_bulk_sq = bulk_sound_speed_sq(mu, P[j], volume, material.rho0, material.c1, material.c2, material.c3,
                                        material.gamma0)
        c_long = math.sqrt(max(c_bulk_sq, 0.0) + four_thirds_G * volume)
        q = artificial_viscosity(du, volume, c_long, numerics.q1, numerics.q2)
        s_trial = s[j] + four_thirds_G * strain_rate * dt
        s_new, d_eps, eps_p[j], hard[j], flow_floor[j], floor_hotter[j], floor_T[j] = plastic_return(
            s_trial, T_cell, strain_rate, P[j], eta, G, eps_p[j], hard[j], flow_floor[j], floor_hotter[j], floor_T[j],
            strength, material)
        dV = dt * du / mass[j]
        work_dev = 0.5 * (s[j] + s_new) * strain_rate * dt * volume
        p_cold = cold_pressure(mu, material.c1, material.c2, material.c3)
        E_new = energy_update(E[j], P[j], p_cold, q, dV, work_dev, g_rho0)
        P_new = p_cold + g_rho0 * E_new
        if not (E_new == E_new and P_new == P_new):
            return STATUS_NAN, j, max_signal_rate
        E[j] = E_new
        P[j] = P_new
        s[j] = s_new
        length[j] = new_length
        sigma[j] = -(P_new + q) + s_new
        if j > gap:
            peaks[0] = max(peaks[0], d_eps / dt)
            peaks[1] = max(peaks[1], material.T_ref + E_new / material.cv)
            peaks[2] = max(peaks[2], eps_p[j])
        max_signal_rate = max(max_signal_rate, signal_speed(du, c_long, numerics.q1, numerics.q2) / new_length)
    return STATUS_OK, -1, max_signal_rate


@njit(cache=True, error_model="numpy")
def grow_window(sigma, lo, hi):
    """The active nodes grow by one where the cell beyond them has started to move (stress != 0)."""
    N = sigma.shape[0] - 1
    if lo > 0 and sigma[lo - 1] != 0.0:
        lo -= 1
    if hi < N + 1 and sigma[hi] != 0.0:
        hi += 1
    return lo, hi


@njit(cache=True, error_model="numpy")
def simulate(nf, nt, dx, velocity, initial, strength, material, numerics, t_out):
    """Run to t_out[-1] (us): a `KernelResult` (free-surface velocity and total energy at t_out, status,
    failed cell and time, steps, the maxima over the target's cells).

    Args:
        nf, nt: cells across the flyer and the target.
        dx: cell size (cm).
        velocity: impact velocity of the flyer (cm/us).
        initial: `InitialState` of both plates (g/cc, (cm/us)^2).
        strength: `Strength` (Johnson-Cook: Mbar, -, 1/us) or `LawStrength` (a law's tuple and G in Mbar).
        material: `Material` (code units).
        numerics: `Numerics` (artificial viscosity, CFL, time steps in us).
        t_out: output times (us), t_out[0] = 0.
    """
    nodes, cells = initial_mesh(nf, nt, dx, velocity, initial, strength, material)
    u = nodes.u
    N = nf + nt
    gap = nf
    g_rho0 = material.gamma0 * material.rho0
    n_out = t_out.shape[0]
    v_out = np.zeros(n_out)
    energy_out = np.zeros(n_out)
    energy_out[0] = total_energy(nodes, cells)
    peaks = np.array([0.0, material.T_ref + initial.E / material.cv, 0.0])
    k_out = 1
    t = 0.0
    dt = numerics.dt_initial
    u_fs_prev, t_fs_prev = 0.0, 0.0
    lo, hi = gap, gap + 1                       # active nodes
    steps = 0
    while k_out < n_out:
        approach_speed = u[gap] - u[gap + 1]
        accelerate_nodes(nodes, cells.sigma, lo, hi, dt)
        close_contact(nodes, cells, gap, dt, max(approach_speed, 0.0), g_rho0)
        status, cell, max_signal_rate = update_cells(nodes, cells, gap, lo, hi, dt, strength, material, numerics,
                                                     peaks)
        if status != STATUS_OK:
            return KernelResult(v_out, energy_out, status, cell, t, steps, peaks[0], peaks[1], peaks[2])
        lo, hi = grow_window(cells.sigma, lo, hi)
        # free-surface velocity (time-centred at t + dt/2), linearly interpolated onto t_out
        t_mid = t + 0.5 * dt
        while k_out < n_out and t_out[k_out] <= t_mid:
            w = (t_out[k_out] - t_fs_prev) / (t_mid - t_fs_prev)
            v_out[k_out] = u_fs_prev + w * (u[N + 1] - u_fs_prev)
            energy_out[k_out] = total_energy(nodes, cells)
            k_out += 1
        u_fs_prev, t_fs_prev = u[N + 1], t_mid
        t += dt
        steps += 1
        dt = min(numerics.cfl / max_signal_rate, DT_GROWTH * dt)
        if dt < DT_FLOOR_US:
            return KernelResult(v_out, energy_out, STATUS_DT_COLLAPSE, -1, t, steps, peaks[0], peaks[1], peaks[2])
    return KernelResult(v_out, energy_out, STATUS_OK, -1, t, steps, peaks[0], peaks[1], peaks[2])
