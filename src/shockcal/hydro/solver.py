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
   only), the cell's shear modulus, elastic trial deviator and return onto the strength law
   (`shockcal.hydro.plastic_return`: elastic inside the rate-free flow stress, skipped while the trial lies
   inside the cell's flow-stress floor; outside, the consistent return at the step's plastic strain rate,
   `shockcal.hydro.consistent_return`), energy equation, EOS;
4. time step: CFL on the longitudinal sound speed, viscosity included (`signal_speed`), growth
   limited to 10%.
The material, strength and numerics parameters travel as named tuples in code units
(`shockcal.hydro.state`: `Material`, `LawStrength` for any law, `Numerics`; `shockcal.units`
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

import numpy as np
from numba import njit

from shockcal.hydro.eos import bulk_sound_speed_sq, cold_pressure
from shockcal.hydro.plastic_return import cell_shear_modulus, initial_hardening, plastic_return
from shockcal.hydro.state import (
    STATUS_DT_COLLAPSE,
    STATUS_NAN,
    STATUS_NEGATIVE_VOLUME,
    STATUS_OK,
    Cells,
    KernelResult,
    Nodes,
)

DT_FLOOR_US = 1.0e-12
DT_GROWTH = 1.1            # the time step grows by at most 10% a step


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
                  np.zeros(N + 1), hard, np.zeros(N + 1), np.zeros(N + 1), np.full(N + 1, np.inf), np.zeros(N + 1),
                  np.zeros(N + 1), np.zeros(N + 1), np.zeros(N + 1))
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
    power_T, power, x_warm, rate_warm = cells.power_T, cells.power, cells.x_warm, cells.rate_warm
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
        s_new, d_eps, eps_p[j], hard[j], flow_floor[j], floor_hotter[j], floor_T[j], memory = plastic_return(
            s_trial, T_cell, dt, P[j], eta, G, eps_p[j], hard[j], flow_floor[j], floor_hotter[j], floor_T[j],
            strength, material, (power_T[j], power[j], x_warm[j], rate_warm[j]))
        power_T[j], power[j], x_warm[j], rate_warm[j] = memory
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
def outputs_until(t_out, t_end):
    """How many of the output times t_out (us, increasing) lie at or before t_end (us)."""
    return np.searchsorted(t_out, t_end, side="right")


@njit(cache=True, error_model="numpy")
def simulate(nf, nt, dx, velocity, initial, strength, material, numerics, t_out, rise_threshold, after_rise):
    """Run to t_out[-1] (us), or to `after_rise` past the first output whose free-surface velocity exceeds
    `rise_threshold`: a `KernelResult` (free-surface velocity and total energy at t_out, status, failed cell
    and time, steps, the maxima over the target's cells, how many outputs the run was to reach). A run that
    ends after the rise takes the same steps as the longer run up to its end, so its outputs are that run's.

    Args:
        nf, nt: cells across the flyer and the target.
        dx: cell size (cm).
        velocity: impact velocity of the flyer (cm/us).
        initial: `InitialState` of both plates (g/cc, (cm/us)^2).
        strength: `LawStrength` (a law's tuple and G in Mbar).
        material: `Material` (code units).
        numerics: `Numerics` (artificial viscosity, CFL, time steps in us).
        t_out: output times (us), t_out[0] = 0.
        rise_threshold: free-surface velocity (cm/us) whose first crossing starts the end's countdown; inf: never.
        after_rise: simulated time (us) after that output; the run ends at the last output time within it.
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
    risen = False                               # the free surface has passed rise_threshold
    while k_out < n_out:
        approach_speed = u[gap] - u[gap + 1]
        accelerate_nodes(nodes, cells.sigma, lo, hi, dt)
        close_contact(nodes, cells, gap, dt, max(approach_speed, 0.0), g_rho0)
        status, cell, max_signal_rate = update_cells(nodes, cells, gap, lo, hi, dt, strength, material, numerics,
                                                     peaks)
        if status != STATUS_OK:
            return KernelResult(v_out, energy_out, status, cell, t, steps, peaks[0], peaks[1], peaks[2], n_out)
        lo, hi = grow_window(cells.sigma, lo, hi)
        # free-surface velocity (time-centred at t + dt/2), linearly interpolated onto t_out
        t_mid = t + 0.5 * dt
        while k_out < n_out and t_out[k_out] <= t_mid:
            w = (t_out[k_out] - t_fs_prev) / (t_mid - t_fs_prev)
            v_out[k_out] = u_fs_prev + w * (u[N + 1] - u_fs_prev)
            energy_out[k_out] = total_energy(nodes, cells)
            if not risen and v_out[k_out] > rise_threshold:
                n_out = min(n_out, outputs_until(t_out, t_out[k_out] + after_rise))
                risen = True
            k_out += 1
        u_fs_prev, t_fs_prev = u[N + 1], t_mid
        t += dt
        steps += 1
        dt = min(numerics.cfl / max_signal_rate, DT_GROWTH * dt)
        if dt < DT_FLOOR_US:
            return KernelResult(v_out, energy_out, STATUS_DT_COLLAPSE, -1, t, steps, peaks[0], peaks[1], peaks[2],
                                n_out)
    return KernelResult(v_out, energy_out, STATUS_OK, -1, t, steps, peaks[0], peaks[1], peaks[2], n_out)
