"""Staggered-grid 1D Lagrangian solver for a flyer plate striking a target (uniaxial strain).

Units inside: cm, us, g/cc, Mbar (1 Mbar = 1 g/cc (cm/us)^2); specific energy in (cm/us)^2.

Mesh: nodes 0..N+1, cells 0..N, cell j between nodes j and j+1. The flyer's cells are 0..nf-1,
the target's nf+1..N; cell nf is the contact gap between the flyer's rear node nf and the
target's front node nf+1 (no mass, no stress, its length is the gap). Both outer nodes are free
surfaces. Each step (leapfrog):
1. nodes: u += dt (sigma_right - sigma_left) / m_node, sigma = -(P + q) + s;
2. contact: if the gap would close, the two interface nodes take their common momentum velocity
   and the energy an impact dissipates goes to the interface cells; under tension the nodes
   separate, which opens the interface;
3. cells: length from the node velocities, strain rate, artificial viscosity (compression only),
   elastic trial deviator and Johnson-Cook radial return, energy equation, EOS;
4. time step: CFL on the longitudinal sound speed, viscosity included, growth limited to 10%.
Only the region the waves have reached is updated: an undisturbed cell has exactly zero stress,
so its nodes keep their initial velocities bit for bit, and the active window grows by one node
when the stress of the cell beyond it becomes non-zero.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np
from numba import njit

from shockcal.config import end_time_us
from shockcal.hydro.eos import bulk_sound_speed_sq, cold_pressure
from shockcal.hydro.strength import flow_stress, hardening, radial_return, thermal_factor

J_PER_KG = 1.0e-8          # 1 J/kg in (cm/us)^2
PER_S = 1.0e-6             # 1 /s in 1/us
CM_US_TO_M_S = 1.0e4
STATUS_OK, STATUS_NEGATIVE_VOLUME, STATUS_NAN, STATUS_DT_COLLAPSE = 0, 1, 2, 3
FAILURE_REASONS = {STATUS_NEGATIVE_VOLUME: "negative cell volume", STATUS_NAN: "NaN in cell state",
                   STATUS_DT_COLLAPSE: "time step collapsed"}
DT_FLOOR_US = 1.0e-12


@njit(cache=True, error_model="numpy")
def _total_energy(u, node_mass, E, cell_mass):
    """Kinetic + internal energy per unit area (Mbar cm)."""
    kinetic = 0.0
    for i in range(u.shape[0]):
        kinetic += 0.5 * node_mass[i] * u[i] * u[i]
    internal = 0.0
    for j in range(E.shape[0]):
        internal += cell_mass[j] * E[j]
    return kinetic + internal


@njit(cache=True, error_model="numpy")
def _collide(u, node_mass, E, P, sigma, cell_mass, gap, g_rho0, approach_speed):
    """Interface nodes in contact move together (momentum conserved). A collision between nodes
    that approached at `approach_speed` before this step (the impact) dissipates
    0.5 mu approach_speed^2; that energy goes into the two interface cells, as a shock would put it.
    Nodes already moving together lose nothing: merging them is the combined node's momentum update."""
    a, b = gap, gap + 1
    common = (node_mass[a] * u[a] + node_mass[b] * u[b]) / (node_mass[a] + node_mass[b])
    u[a] = common
    u[b] = common
    reduced_mass = node_mass[a] * node_mass[b] / (node_mass[a] + node_mass[b])
    dissipated = 0.5 * reduced_mass * approach_speed * approach_speed
    for j in (gap - 1, gap + 1):
        dE = 0.5 * dissipated / cell_mass[j]
        E[j] += dE
        P[j] += g_rho0 * dE
        sigma[j] -= g_rho0 * dE


@njit(cache=True, error_model="numpy")
def _simulate(nf, nt, dx, velocity, G, A, B, C, n, m, rho0, c1, c2, c3, gamma0, T_ref, T_melt, cv,
              rate_ref, q1, q2, cfl, dt_initial, dt_max, t_out):
    """Run to t_out[-1]; returns (v_free_surface, energy_at_outputs, status, fail_cell, fail_time,
    n_steps, max_plastic_rate, max_T, max_eps_p), the maxima over the target's cells."""
    N = nf + nt
    gap = nf
    cell_mass = np.full(N + 1, rho0 * dx)
    cell_mass[gap] = 0.0
    length = np.full(N + 1, dx)
    length[gap] = 0.0
    E = np.zeros(N + 1)
    P = np.zeros(N + 1)
    q = np.zeros(N + 1)
    s = np.zeros(N + 1)
    sigma = np.zeros(N + 1)
    eps_p = np.zeros(N + 1)
    hard = np.full(N + 1, hardening(A, B, n, 0.0))
    # a lower bound of each cell's flow stress, valid while its temperature stays <= floor_T:
    # a trial stress inside it is elastic without evaluating pow/log (JC rate factor >= 1, thermal
    # factor falling with T, hardening growing with eps_p)
    flow_floor = np.zeros(N + 1)
    floor_T = np.full(N + 1, np.inf)
    u = np.zeros(N + 2)
    u[: nf + 1] = velocity
    node_mass = np.empty(N + 2)
    node_mass[0] = 0.5 * cell_mass[0]
    for i in range(1, N + 1):
        node_mass[i] = 0.5 * (cell_mass[i - 1] + cell_mass[i])
    node_mass[N + 1] = 0.5 * cell_mass[N]

    n_out = t_out.shape[0]
    v_out = np.zeros(n_out)
    energy_out = np.zeros(n_out)
    energy_out[0] = _total_energy(u, node_mass, E, cell_mass)
    k_out = 1
    t = 0.0
    dt = dt_initial
    u_fs_prev, t_fs_prev = 0.0, 0.0
    lo, hi = gap, gap + 1                       # active nodes
    steps = 0
    max_rate, max_T, max_eps = 0.0, T_ref, 0.0
    four_thirds_G = 4.0 * G / 3.0
    g_rho0 = gamma0 * rho0
    inv_T_range = 1.0 / (T_melt - T_ref)

    while k_out < n_out:
        # 1. momentum
        approach_speed = u[gap] - u[gap + 1]
        for i in range(lo, hi + 1):
            left = sigma[i - 1] if i > 0 else 0.0
            right = sigma[i] if i <= N else 0.0
            u[i] += dt * (right - left) / node_mass[i]
        # 2. contact
        closing = length[gap] + dt * (u[gap + 1] - u[gap])
        if closing <= 0.0:
            _collide(u, node_mass, E, P, sigma, cell_mass, gap, g_rho0, max(approach_speed, 0.0))
        length[gap] = max(length[gap] + dt * (u[gap + 1] - u[gap]), 0.0)
        # 3. cells
        max_signal_rate = cfl / dt_max         # (signal speed / cell length), the CFL limit is cfl / max
        for j in range(max(lo - 1, 0), min(hi, N) + 1):
            if j == gap:
                continue
            du = u[j + 1] - u[j]
            old_length = length[j]
            new_length = old_length + dt * du
            if not new_length > 0.0:
                return v_out, energy_out, STATUS_NEGATIVE_VOLUME, j, t, steps, max_rate, max_T, max_eps
            strain_rate = 2.0 * du / (old_length + new_length)
            volume = new_length / cell_mass[j]       # specific volume 1/rho
            mu = 1.0 / (rho0 * volume) - 1.0
            c_bulk_sq = bulk_sound_speed_sq(mu, P[j], volume, rho0, c1, c2, c3, gamma0)
            c_long = math.sqrt(max(c_bulk_sq, 0.0) + four_thirds_G * volume)
            q_new = (q2 * du * du - q1 * c_long * du) / volume if du < 0.0 else 0.0
            # strength: elastic trial, Johnson-Cook flow stress, radial return
            s_trial = s[j] + four_thirds_G * strain_rate * dt
            T_cell = T_ref + E[j] / cv
            if 1.5 * abs(s_trial) <= flow_floor[j] and T_cell <= floor_T[j]:
                s_new, d_eps = s_trial, 0.0
            else:
                thermal = thermal_factor(m, (T_cell - T_ref) * inv_T_range)
                flow = flow_stress(hard[j], thermal, C, strain_rate, rate_ref)
                s_new, d_eps = radial_return(s_trial, flow, G)
                if d_eps > 0.0:
                    eps_p[j] += d_eps
                    hard[j] = hardening(A, B, n, eps_p[j])
                flow_floor[j] = hard[j] * thermal     # the rate factor is >= 1, thermal(T) falls with T
                floor_T[j] = T_cell
            # energy: dE = -(P + q) dV + s_mean * strain_rate * dt / rho, P implicit (trapezoid)
            dV = dt * du / cell_mass[j]
            work_dev = 0.5 * (s[j] + s_new) * strain_rate * dt * volume
            p_cold = cold_pressure(mu, c1, c2, c3)
            E_new = (E[j] - (0.5 * (P[j] + p_cold) + q_new) * dV + work_dev) / (1.0 + 0.5 * g_rho0 * dV)
            P[j] = p_cold + g_rho0 * E_new
            if not (E_new == E_new and P[j] == P[j]):
                return v_out, energy_out, STATUS_NAN, j, t, steps, max_rate, max_T, max_eps
            E[j] = E_new
            q[j] = q_new
            s[j] = s_new
            length[j] = new_length
            sigma[j] = -(P[j] + q_new) + s_new
            if j > gap:
                max_rate = max(max_rate, d_eps / dt)      # plastic rate: a diagnostic only
                max_T = max(max_T, T_ref + E_new / cv)
                max_eps = max(max_eps, eps_p[j])
            # 4. time step: dt = cfl L / (a + sqrt(a^2 + c^2)), a the viscous signal speed
            a_visc = (q1 * c_long + 2.0 * q2 * abs(du)) if du < 0.0 else 0.0
            signal = a_visc + math.sqrt(a_visc * a_visc + c_long * c_long) if du < 0.0 else c_long
            max_signal_rate = max(max_signal_rate, signal / new_length)
        dt_next = cfl / max_signal_rate
        # grow the active window where a cell beyond it has started to move
        if lo > 0 and sigma[lo - 1] != 0.0:
            lo -= 1
        if hi < N + 1 and sigma[hi] != 0.0:
            hi += 1
        # free-surface velocity (time-centred at t + dt/2), linearly interpolated onto t_out
        t_mid = t + 0.5 * dt
        while k_out < n_out and t_out[k_out] <= t_mid:
            w = (t_out[k_out] - t_fs_prev) / (t_mid - t_fs_prev)
            v_out[k_out] = u_fs_prev + w * (u[N + 1] - u_fs_prev)
            energy_out[k_out] = _total_energy(u, node_mass, E, cell_mass)
            k_out += 1
        u_fs_prev, t_fs_prev = u[N + 1], t_mid
        t += dt
        steps += 1
        dt = min(dt_next, 1.1 * dt)
        if dt < DT_FLOOR_US:
            return v_out, energy_out, STATUS_DT_COLLAPSE, -1, t, steps, max_rate, max_T, max_eps
    return v_out, energy_out, STATUS_OK, -1, t, steps, max_rate, max_T, max_eps


@dataclass
class RunResult:
    """One hydrocode run: free-surface velocity history and diagnostics (user units)."""

    t_us: np.ndarray
    v_m_s: np.ndarray
    status: str                      # "ok" or "failed"
    reason: str = ""
    max_strain_rate_per_us: float = float("nan")
    max_temperature_K: float = float("nan")
    max_plastic_strain: float = float("nan")
    energy_error: float = float("nan")
    n_steps: int = 0
    wall_time_s: float = 0.0
    energy_history: np.ndarray = field(default=None, repr=False)


def run_shot(params, shot: dict, config: dict, end_us: float | None = None) -> RunResult:
    """Simulate one shot to `end_us` (default: `end_time_us(config, shot)`). `params` is a
    shockcal.design.ShotParameters (Mbar, cm/us)."""
    material, hydro, eos = config["material"], config["hydro"], config["material"]["eos"]
    dx = hydro["cell_size_um"] * 1e-4
    nf = max(int(round(shot["flyer_mm"] * 0.1 / dx)), 1)
    nt = max(int(round(shot["target_mm"] * 0.1 / dx)), 1)
    dt_out = hydro["output_dt_ns"] * 1e-3
    end_us = end_time_us(config, shot) if end_us is None else end_us
    t_out = np.arange(int(round(end_us / dt_out)) + 1) * dt_out
    start = time.perf_counter()
    v, energy, status, cell, t_fail, steps, max_rate, max_T, max_eps = _simulate(
        nf, nt, dx, params.velocity_cm_us, params.shear_modulus_Mbar, params.A, params.B, params.C, params.n,
        params.m, material["rho0_g_cc"], eos["c1_Mbar"], eos["c2_Mbar"], eos["c3_Mbar"], eos["gamma0"],
        material["T_ref_K"], material["T_melt_K"], material["cv_J_per_kg_K"] * J_PER_KG,
        material["strain_rate_ref_per_s"] * PER_S, hydro["q_linear"], hydro["q_quadratic"], hydro["cfl"],
        hydro["dt_initial_us"], hydro["dt_max_us"], t_out)
    wall = time.perf_counter() - start
    reason = ""
    if status != STATUS_OK:
        where = f" in cell {cell}" if cell >= 0 else ""
        body = "" if cell < 0 else (" (flyer)" if cell < nf else " (target)")
        reason = f"{FAILURE_REASONS[status]}{where}{body} at t = {t_fail:.5f} us after {steps} steps"
    reached = energy[: max(1, np.count_nonzero(energy) or 1)]
    energy_error = float(np.max(np.abs(reached - energy[0])) / energy[0])
    return RunResult(t_out, v * CM_US_TO_M_S, "ok" if status == STATUS_OK else "failed", reason,
                     max_rate, max_T, max_eps, energy_error, int(steps), wall, energy)
