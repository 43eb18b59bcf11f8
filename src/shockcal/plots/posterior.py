"""Posterior figures: 7 (marginals per calibration, rows, with the config's reference sets) and 8 (joint pairs).

Posterior tables hold one column per calibrated input in its declared unit, the config's
`inputs.<name>.unit` (Table IV units for Johnson-Cook; plus bookkeeping columns such as lambda_y and
log_likelihood, which are ignored). Each is drawn in the unit a user reads (`display_columns`: MPa for
stresses, GPa for the shots' shear-modulus inputs, m/s for velocities). Axes span the prior box in
those units, widened where a value of the reference sets given lies outside it (the study's come from
`study.reference_sets` through `shockcal.study.references.drawn_sets`, which the figure catalogue passes
in); figure 7 draws them as vertical lines.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pandas as pd

from shockcal.plots.style import COLORS, figure_legend, input_label, no_data, styled, subplots
from shockcal.units import unit_factor, user_columns, user_units

REFERENCE_STYLES = ("-", "--", "-.", ":")   # line styles of the reference sets, in turn
N_BINS = 40


def _reference_lines(references: Sequence, config: dict) -> list[tuple[str, str, dict[str, float]]]:
    """Reference sets (each with a `label` and `values` {input: (value, unit)}, as
    `shockcal.study.references.ReferenceSet`), each as (legend label, line style, {input: value in its
    display unit})."""
    columns = display_columns(config)
    lines = []
    for i, ref in enumerate(references):
        values = {name: value * unit_factor(unit, columns[name][1]) for name, (value, unit) in ref.values.items()}
        lines.append((ref.label, REFERENCE_STYLES[i % len(REFERENCE_STYLES)], values))
    return lines


def display_columns(config: dict) -> dict[str, tuple[str, str, float]]:
    """Each input -> (its name with the unit, its display unit, the factor from its declared unit):
    `shockcal.units.user_columns`, the shots' `shear_modulus_inputs` read as moduli."""
    moduli = {name for shot in config["shots"].values() for name in shot["shear_modulus_inputs"]}
    units = {name: box["unit"] for name, box in config["inputs"].items()}
    return user_columns(units, user_units(units, moduli))


def to_display(name: str, values, config: dict):
    """Values of input `name` converted from its declared unit to its display unit."""
    return np.asarray(values, dtype=float) * display_columns(config)[name][2]


def display_label(name: str, config: dict) -> str:
    """Axis label of input `name` with its display unit."""
    return input_label(name, display_columns(config)[name][1])


def display_limits(name: str, config: dict, references: Sequence = ()) -> tuple[float, float]:
    """Prior box of input `name` in display units, widened to show any reference set's value outside it."""
    box = config["inputs"][name]
    lo, hi = to_display(name, [box["min"], box["max"]], config)
    refs = [values[name] for _, _, values in _reference_lines(references, config) if name in values]
    lo, hi = min([lo, *refs]), max([hi, *refs])
    pad = 0.02 * (hi - lo)
    return lo - pad, hi + pad


def _shade_outside_box(ax, name: str, config: dict, references: Sequence) -> None:
    """Grey shading over the parts of the axis outside the prior box."""
    box = config["inputs"][name]
    lo, hi = to_display(name, [box["min"], box["max"]], config)
    left, right = display_limits(name, config, references)
    ax.axvspan(left, lo, color=COLORS["prior"], lw=0)
    ax.axvspan(hi, right, color=COLORS["prior"], lw=0)


def _draw_reference_sets(ax, name: str, config: dict, references: Sequence) -> None:
    """A vertical line per reference set that gives input `name`, labelled for the legend."""
    for label, ls, values in _reference_lines(references, config):
        if name in values:
            ax.axvline(values[name], color=COLORS["reference"], ls=ls, lw=1.1, label=label)


@styled
def fig07_marginals(posteriors: dict[str, pd.DataFrame | None], config: dict, references: Sequence = ()):
    """Histograms of each input (columns) for each calibration (rows: shots, then joint), with a vertical
    line per value of the `references` (see `_reference_lines`; a value outside the prior box widens the axis).

    `posteriors` maps a calibration name to its samples; None or an empty table gives a "no data" row.
    """
    names = list(config["inputs"])     # every input, in the design's order
    rows = list(posteriors)
    fig, axes = subplots(len(rows), len(names), width=1.55 * len(names), height=1.35 * len(rows) + 0.9)
    for r, calib in enumerate(rows):
        samples = posteriors[calib]
        for c, name in enumerate(names):
            ax = axes[r, c]
            if samples is None or samples.empty:
                no_data(ax, "posterior missing" if samples is None else "posterior empty")
            elif name not in samples.columns:
                ax.set_yticks([])
                ax.set_xticks([])
                ax.text(0.5, 0.5, f"not an input\nof {calib}", transform=ax.transAxes, ha="center",
                        va="center", fontsize=7, color="0.5")
            else:
                values = to_display(name, samples[name], config)
                limits = display_limits(name, config, references)
                ax.hist(values, bins=N_BINS, range=limits, density=True, color=COLORS["posterior"], alpha=0.75,
                        lw=0)
                ax.set_xlim(limits)
                ax.set_yticks([])
                _shade_outside_box(ax, name, config, references)
                _draw_reference_sets(ax, name, config, references)
            if r == len(rows) - 1:
                ax.set_xlabel(display_label(name, config))
            ax.tick_params(axis="x", labelsize=6.5)
        axes[r, 0].set_ylabel(calib, fontsize=10, fontweight="bold")
    figure_legend(fig, axes, title="posterior (blue); grey: outside the prior box")
    return fig


def _density_levels(hist, masses=(0.5, 0.9)):
    """Density thresholds enclosing the given probability masses of a 2-D histogram (highest first)."""
    flat = np.sort(hist.ravel())[::-1]
    cum = np.cumsum(flat) / flat.sum()
    levels = [flat[min(np.searchsorted(cum, m), len(flat) - 1)] for m in masses]
    return sorted(set(levels))


@styled
def fig08_pairs(samples: pd.DataFrame | None, config: dict, bins: int = 30, references: Sequence = ()):
    """Joint posterior: marginal densities on the diagonal, 50% and 90% contours below it, on axes that
    show the `references`' values (as fig07_marginals)."""
    from scipy.ndimage import gaussian_filter

    names = list(config["inputs"])     # every input, in the design's order
    k = len(names)
    fig, axes = subplots(k, k, width=1.25 * k + 0.5, height=1.25 * k + 0.5)
    if samples is None or samples.empty:
        for ax in axes.flat:
            ax.set_axis_off()
        axes[k // 2, k // 2].set_axis_on()
        no_data(axes[k // 2, k // 2], "joint posterior missing or empty")
        return fig
    missing = [n for n in names if n not in samples.columns]
    values = {n: to_display(n, samples[n], config) for n in names if n not in missing}
    limits = {n: display_limits(n, config, references) for n in names}
    for i, yname in enumerate(names):
        for j, xname in enumerate(names):
            ax = axes[i, j]
            if j > i:
                ax.set_axis_off()
                continue
            if xname in missing or yname in missing:
                no_data(ax, f"{xname if xname in missing else yname} not in posterior")
                continue
            if i == j:
                ax.hist(values[xname], bins=bins, range=limits[xname], density=True,
                        color=COLORS["posterior"], alpha=0.75, lw=0)
                ax.set_yticks([])
            else:
                hist, xe, ye = np.histogram2d(values[xname], values[yname], bins=bins,
                                              range=[limits[xname], limits[yname]])
                hist = gaussian_filter(hist, 1.0)
                if hist.sum() > 0:
                    xc, yc = 0.5 * (xe[1:] + xe[:-1]), 0.5 * (ye[1:] + ye[:-1])
                    ax.contourf(xc, yc, hist.T, levels=[*_density_levels(hist), hist.max() + 1],
                                colors=[COLORS["posterior"]], alpha=0.35)
                    ax.contour(xc, yc, hist.T, levels=_density_levels(hist), colors=[COLORS["posterior"]],
                               linewidths=0.8)
                ax.set_ylim(limits[yname])
            ax.set_xlim(limits[xname])
            ax.tick_params(labelsize=6)
            if i == k - 1:
                ax.set_xlabel(display_label(xname, config), fontsize=7.5)
            else:
                ax.set_xticklabels([])
            if j == 0 and i > 0:
                ax.set_ylabel(display_label(yname, config), fontsize=7.5)
            elif i != j:
                ax.set_yticklabels([])
    fig.suptitle(f"Joint posterior, {len(samples):,} samples: densities (diagonal), 50% and 90% regions")
    return fig
