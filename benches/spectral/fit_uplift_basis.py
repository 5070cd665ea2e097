#!/usr/bin/env python3
"""Fit the six coloured basis spectra of Prism's RGB uplift (src/spectrum/uplift.rs).

The uplift writes an RGB colour as white + a secondary + a primary basis
spectrum, weighted as in Smits 1999. An RGB renderer multiplies colours
channel by channel; a spectral one multiplies spectra and only then projects
to RGB. The two agree on every product of two uplifted colours exactly when
the basis has RGB's multiplication table: RGB(S_i · S_j) = t_i ∘ t_j for
every pair of basis spectra, where t_i is the RGB each must have (red (1,0,0),
cyan (0,1,1), ...), because the uplift is linear. No spectra in [0, 1] can
meet that exactly (the matching functions overlap, so no box spectrum has an
RGB of exactly (1, 0, 0)), so this script finds the basis that comes closest:

  minimise   sum over pairs i <= j of |RGB(S_i S_j) - t_i t_j|^2
             + smoothness * sum_k |second difference of S_k|^2
  subject to RGB(S_k) = t_k exactly (the round trip) and 0 <= S_k <= 1,

starting from Smits' own table (corrected to this film as in uplift.rs),
by sequential least squares (scipy's SLSQP: about 15 CPU minutes). L-BFGS-B
with the round trip as a penalty or an augmented Lagrangian is a hundred
times faster but stopped in worse local minima (RMS defect 0.0146-0.0177
against SLSQP's 0.013). The renderer removes what residual is left, and
that of printing six digits, by its exact x, y, z correction. All integrals are exact for
the piecewise-linear spectra the renderer reads: on each 5 nm interval the
product of two basis spectra and a matching function is a cubic, which
Simpson's rule integrates exactly.

Usage: python3 benches/spectral/fit_uplift_basis.py [--iterations N] [--smoothness W]
writes src/spectrum/uplift/fitted_basis.rs and prints the defect before and
after. Needs numpy and scipy (pip install numpy scipy); the renderer does not.
"""
import argparse
import pathlib
import re

import numpy as np
from scipy.optimize import minimize

ROOT = pathlib.Path(__file__).resolve().parents[2]
NAMES = ["cyan", "magenta", "yellow", "red", "green", "blue"]
TARGETS = np.array([[0, 1, 1], [1, 0, 1], [1, 1, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)
# IEC 61966-2-1 XYZ -> linear sRGB, as src/spectrum/sensor.rs.
XYZ_TO_SRGB = np.array([[3.2406, -1.5372, -0.4986], [-0.9689, 1.8758, 0.0415], [0.0557, -0.2040, 1.0570]])


def read_cie_table():
    """The CIE 1931 table exactly as the renderer has it (src/spectrum/cie.rs)."""
    text = (ROOT / "src/spectrum/cie.rs").read_text()
    start = text.index("CIE_1931_2DEG")
    block = text[text.index("= [", start):]
    block = block[: block.index("];")]
    rows = re.findall(r"\[([0-9.e\-]+),\s*([0-9.e\-]+),\s*([0-9.e\-]+)\]", block)
    table = np.array(rows, float)
    assert table.shape == (95, 3), table.shape
    return table


def read_smits_table():
    """Smits 1999, table 1 (cyan, magenta, yellow, red, green, blue at ten bin
    centres over 380-720 nm), exactly as src/spectrum/uplift.rs has it."""
    text = (ROOT / "src/spectrum/uplift.rs").read_text()
    block = text[text.index("= [", text.index("const SMITS_1999")):]
    block = block[: block.index("];")]
    rows = [re.findall(r"[0-9.]+", row) for row in re.findall(r"\[([^\]]+)\]", block)]
    table = np.array(rows, float)
    assert table.shape == (6, 10), table.shape
    return table


CMF = read_cie_table()
SMITS_1999 = read_smits_table()
GRID = 360.0 + 5.0 * np.arange(95)
# Simpson nodes: the grid points and the interval midpoints; a grid table is
# read there by linear interpolation, which is what the renderer does.
NODES = 2 * 95 - 1
INTERPOLATE = np.zeros((NODES, 95))
for i in range(95):
    INTERPOLATE[2 * i, i] = 1.0
for i in range(94):
    INTERPOLATE[2 * i + 1, i] = INTERPOLATE[2 * i + 1, i + 1] = 0.5
SIMPSON = np.zeros(NODES)
for i in range(94):
    SIMPSON[2 * i] += 5.0 / 6.0
    SIMPSON[2 * i + 1] += 4.0 * 5.0 / 6.0
    SIMPSON[2 * i + 2] += 5.0 / 6.0
CMF_NODES = INTERPOLATE @ CMF
Y_INTEGRAL = SIMPSON @ CMF_NODES[:, 1]
E_RGB = XYZ_TO_SRGB @ (SIMPSON @ CMF_NODES) / Y_INTEGRAL
# RGB of a function given at the nodes (white-balanced so that 1 -> (1,1,1)).
RGB_OF_NODES = (np.diag(1.0 / E_RGB) @ XYZ_TO_SRGB @ (SIMPSON[:, None] * CMF_NODES).T) / Y_INTEGRAL
RGB_OF_TABLE = RGB_OF_NODES @ INTERPOLATE
PAIRS = [(i, j) for i in range(6) for j in range(i, 6)]


def smits_corrected():
    """Smits' table on the grid, plus the x, y, z combination that makes it round-trip (as uplift.rs)."""
    x = np.clip((GRID - 397.0) / 34.0, 0.0, 9.0)
    j = np.minimum(x.astype(int), 8)
    t = x - j
    basis = SMITS_1999[:, j] * (1 - t) + SMITS_1999[:, j + 1] * t
    response = RGB_OF_TABLE @ CMF
    return np.array([s + CMF @ np.linalg.solve(response, target - RGB_OF_TABLE @ s) for s, target in zip(basis, TARGETS)])


def defects(basis):
    """RGB(S_i S_j) - t_i t_j for every pair, one row each."""
    nodes = basis @ INTERPOLATE.T
    return np.array([RGB_OF_NODES @ (nodes[i] * nodes[j]) - TARGETS[i] * TARGETS[j] for i, j in PAIRS])


def fit(start, smoothness, iterations):
    second = np.diff(np.eye(95), 2, axis=0)

    def objective(x):
        basis = x.reshape(6, 95)
        nodes = basis @ INTERPOLATE.T
        value, gradient = 0.0, np.zeros((6, NODES))
        for i, j in PAIRS:
            residual = RGB_OF_NODES @ (nodes[i] * nodes[j]) - TARGETS[i] * TARGETS[j]
            value += residual @ residual
            back = 2.0 * (RGB_OF_NODES.T @ residual)
            gradient[i] += nodes[j] * back
            gradient[j] += nodes[i] * back
        gradient = gradient @ INTERPOLATE
        for k in range(6):
            d = second @ basis[k]
            value += smoothness * d @ d
            gradient[k] += 2.0 * smoothness * second.T @ d
        return value, gradient.ravel()

    equality = np.zeros((18, 6 * 95))
    for k in range(6):
        equality[3 * k:3 * k + 3, 95 * k:95 * (k + 1)] = RGB_OF_TABLE
    target = TARGETS.ravel()

    equality_constraint = {"type": "eq", "fun": lambda x: equality @ x - target, "jac": lambda x: equality}
    result = minimize(
        objective, np.clip(start, 0.0, 1.0).ravel(), jac=True, method="SLSQP",
        bounds=[(0.0, 1.0)] * (6 * 95), constraints=[equality_constraint],
        options={"maxiter": iterations, "ftol": 1e-12},
    )
    x = result.x
    print(f"SLSQP: {result.message} after {result.nit} iterations, objective {result.fun:.6g}")
    return np.clip(x.reshape(6, 95), 0.0, 1.0)


def write_rust(basis, path, smoothness, iterations):
    lines = [
        "//! The six coloured basis spectra of the RGB uplift, 360, 365, …, 830 nm.",
        "//!",
        "//! Generated by `benches/spectral/fit_uplift_basis.py "
        f"--iterations {iterations} --smoothness {smoothness:g}`:",
        "//! do not edit by hand. What they minimise, and why: the parent module.",
        "",
        "use crate::spectrum::cie::GRID_POINTS;",
        "",
        "/// Cyan, magenta, yellow, red, green, blue on the spectral grid.",
        "#[rustfmt::skip]",
        "pub const FITTED_BASIS: [[f64; GRID_POINTS]; 6] = [",
    ]
    for name, spectrum in zip(NAMES, basis):
        lines.append(f"    // {name}")
        lines.append("    [")
        values = [f"{v:.6f}" for v in spectrum]
        for i in range(0, 95, 10):
            lines.append("        " + ", ".join(values[i:i + 10]) + ",")
        lines.append("    ],")
    lines.append("];")
    path.write_text("\n".join(lines) + "\n")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--iterations", type=int, default=500)
    parser.add_argument("--smoothness", type=float, default=1e-4)
    parser.add_argument("--output", type=pathlib.Path, default=ROOT / "src/spectrum/uplift/fitted_basis.rs")
    args = parser.parse_args()
    start = smits_corrected()
    basis = fit(start, args.smoothness, args.iterations)
    rms = lambda b: np.sqrt((defects(b) ** 2).mean())
    print(f"multiplication-table defect, RMS over 21 pairs x 3 channels: Smits corrected {rms(start):.4f}, fitted {rms(basis):.4f}")
    print(f"round trip of the fitted table, worst channel: {np.abs(basis @ RGB_OF_TABLE.T - TARGETS).max():.2e}")
    write_rust(basis, args.output, args.smoothness, args.iterations)
    print(f"wrote {args.output}")


if __name__ == "__main__":
    main()
