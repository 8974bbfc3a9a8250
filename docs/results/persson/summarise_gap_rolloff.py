"""The pressure–separation law at larger L/λ_r (docs/persson.md), from the persson_gap runs
that hold the pixel cut-off λ_s = 4 pixels and λ_r/λ_s = 16 while the cell grows:
L/λ_r = 4 (gap_256_512.csv, its 256² rows), 8 (gap_r8_512.csv: 512², roll-off 8, cut-off
128) and 16 (gap_r16_1024.csv: 1024², roll-off 16, cut-off 256).

python docs/results/persson/summarise_gap_rolloff.py   (from the repository root)
Writes gap_rolloff_summary.csv, gap_rolloff_summary.md and gap_rolloff.png, with the fits
of summarise_gap.py (u₀ = −dū/d ln p per sample, mean ± 95 % over samples) over four windows
of p/(E*ḡ), one decade lower than its three as well.
"""
import csv
import math
import pathlib
import statistics

import summarise_gap as gap

HERE = pathlib.Path(__file__).resolve().parent
SERIES = [(4, "gap_256_512.csv", 256), (8, "gap_r8_512.csv", 512), (16, "gap_r16_1024.csv", 1024)]
gap.WINDOWS = [(1e-4, 1e-3)] + gap.WINDOWS


def series():
    """(L/λ_r, rows) for each file present."""
    out = []
    for cells, name, n in SERIES:
        if not (HERE / name).exists():
            continue
        with open(HERE / name) as f:
            data = [{k: (int(v) if k in ("n", "seed", "iterations") else float(v)) for k, v in r.items()}
                    for r in csv.DictReader(f)]
        out.append((cells, [r for r in data if r["n"] == n]))
    return out


def table():
    out = []
    for cells, data in series():
        for row in gap.summarise(data):
            row["lambda_s_pixels"] = 4
            row["cells"] = cells
            out.append(row)
    return out


def markdown(rows):
    lines = ["| p/(E*ḡ) | L/λ_r (N) | H | samples | BEM contact | u₀/h_rms BEM | u₀/h_rms Persson, window (γ=0.45) | ū BEM/Persson | dlnK/dlnp BEM |",
             "|---|---|---|---|---|---|---|---|---|"]
    for t in sorted(rows, key=lambda t: (t["p_min"], t["hurst"], t["cells"])):
        hr = t["rms_height"]
        lines.append("| {lo:g}–{hi:g} | {c} ({n}) | {h:g} | {m} | {amin:.2%}–{amax:.2%} | {u0:.3f} ± {ci:.3f} | {uw:.3f} | {gr:.2f} | {s:.2f} ± {sci:.2f} |".format(
            lo=t["p_min"], hi=t["p_max"], c=t["cells"], n=t["n"], h=t["hurst"], m=t["samples"],
            amin=t["area_min"], amax=t["area_max"], u0=t["u0_bem"] / hr, ci=t["u0_bem_ci95"] / hr,
            uw=t["u0_persson_window"] / hr, gr=t["gap_bem_over_persson"], s=t["stiffness_slope_bem"],
            sci=t["stiffness_slope_bem_ci95"]))
    return "\n".join(lines) + "\n"


def plot():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.5), sharey=True)
    for ax, h in zip(axes, (0.3, 0.8)):
        for (cells, data), c in zip(series(), ("C0", "C1", "C2")):
            curves = [r for r in data if r["hurst"] == h]
            level = lambda r: round(math.log10(r["pressure"]), 6)
            ps = sorted({level(r) for r in curves})
            mean = lambda key, p: statistics.fmean(r[key] / r["rms_height"] for r in curves if level(r) == p)
            g = statistics.fmean(r["rms_gradient"] for r in curves)
            x = [10**p / g for p in ps]
            ax.semilogx(x, [mean("gap_bem", p) for p in ps], "o", color=c, ms=4, label=f"BEM, L/λ_r = {cells}")
            ax.semilogx(x, [mean("gap_persson", p) for p in ps], "-", color=c, lw=1, label=f"Persson γ = 0.45, L/λ_r = {cells}")
        ax.set_xlabel("p / (E* ḡ)")
        ax.set_title(f"H = {h:g}, λ_s = 4 px, λ_r/λ_s = 16, periodic")
        ax.legend(fontsize=7)
    axes[0].set_ylabel("ū / h_rms")
    fig.tight_layout()
    fig.savefig(HERE / "gap_rolloff.png", dpi=110)


def main():
    rows = table()
    with open(HERE / "gap_rolloff_summary.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    (HERE / "gap_rolloff_summary.md").write_text(markdown(rows))
    plot()


if __name__ == "__main__":
    main()
